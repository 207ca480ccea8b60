"""The installed distribution's version: read from its metadata on first use, since
importing :mod:`importlib.metadata` costs each workflow job's client a tenth of its
start (``alfa_bench.__version__`` imports this module)."""

from importlib.metadata import PackageNotFoundError, version

__all__ = ["__version__"]

try:
    __version__ = version("alfa-bench")
except PackageNotFoundError:   # run from sources that were never installed
    __version__ = "0+unknown"
