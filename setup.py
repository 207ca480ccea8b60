"""The package's layout, which pyproject.toml cannot state: the design card keeps data/,
methods/ and analysis/ at the top level; they, the config (with its schema, shipped as
package data), the outputs and the workflow's own helpers (beside the scripts that use
them) install under one package (alfa_bench/: the Python entry point), so that imports
never collide with other packages. Each folder's subpackages are found, not listed, so
that a new one (alfa_bench/live) is never left out of a plain install."""

from setuptools import find_packages, setup

#: each installed package and the folder it comes from
FOLDERS = {"alfa_bench": "alfa_bench", "alfa_bench.config": "config",
           "alfa_bench.data": "data", "alfa_bench.methods": "methods",
           "alfa_bench.analysis": "analysis", "alfa_bench.outputs": "outputs",
           "alfa_bench.workflow": "workflow"}

setup(package_dir=FOLDERS,
      packages=[*FOLDERS, *(f"{name}.{sub}" for name, folder in FOLDERS.items()
                            for sub in find_packages(folder))])
