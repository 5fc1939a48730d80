"""The model builder: a participant's `Model` from its bones (`pipeline`), by morphing the annotated
template onto them and computing cartilage, contact grids and samples, ligament fibres and mass."""

__all__: list[str] = []  # the modules are the API: nothing is imported here
