"""The Numba explicit solver: kernels over arrays and the `simulate` recipe."""
