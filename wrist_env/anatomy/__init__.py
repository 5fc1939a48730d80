"""The anatomy template and what is read from myo-sim: the bones in the RCS, the rebuilt radius cap, the
seated distal row, the ulnar variance, the tendons' loads and the cartilage and ligament annotations."""

__all__: list[str] = []  # the modules are the API: nothing is imported here
