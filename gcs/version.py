"""The installed package's version, as `quadgcs --version` prints it."""

from __future__ import annotations

from importlib.metadata import PackageNotFoundError, version

DISTRIBUTION = "quadgcs"


def package_version() -> str:
    """The version pip installed (pyproject's `version`), or a plain word when run from a bare
    source tree, where there is no installed metadata to read."""
    try:
        return version(DISTRIBUTION)
    except PackageNotFoundError:
        return "unknown (not installed)"
