"""What made a file: the versions of the packages involved, recorded in data sets and models.

Examples
--------
>>> sorted(package_versions("numpy", "no-such-package-xyz"))
['no-such-package-xyz', 'numpy']
>>> package_versions("no-such-package-xyz")["no-such-package-xyz"]
'unknown'
"""

from __future__ import annotations

from importlib import metadata

__all__ = ["package_versions"]


def package_versions(*packages: str) -> dict[str, str]:
    """Installed version of each package, ``"unknown"`` when it is not installed."""
    versions = {}
    for package in packages:
        try:
            versions[package] = metadata.version(package)
        except metadata.PackageNotFoundError:
            versions[package] = "unknown"
    return versions
