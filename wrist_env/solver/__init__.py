"""The Numba explicit solver: kernels over arrays and the `simulate` recipe."""

__all__: list[str] = []  # the modules are the API: nothing is imported here
