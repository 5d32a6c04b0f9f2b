"""Collection settings for the whole repository (the doctests under unstack/ and tests/)."""

#: Deprecated module names: importing them only warns that they moved (tests/test_deprecated_names.py).
collect_ignore = ["unstack/datasets.py", "unstack/figures.py"]
