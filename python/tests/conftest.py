"""Shared fixtures: the checkout's data and the imusysid tool of the build
(IMUSYSID_CLI, set by CTest; else build/imusysid)."""

import os
import pathlib
import subprocess

import pytest

ROOT = pathlib.Path(__file__).resolve().parents[2]


@pytest.fixture(scope="session")
def data_dir():
    return ROOT / "data"


@pytest.fixture(scope="session")
def cli():
    path = os.environ.get("IMUSYSID_CLI", str(ROOT / "build" / "imusysid"))
    if not os.path.exists(path):
        pytest.skip(f"no imusysid tool at {path} (set IMUSYSID_CLI)")

    def run(*args):
        done = subprocess.run([path, *args], capture_output=True, text=True,
                              check=False)
        return done.returncode, done.stdout, done.stderr
    return run


def pytest_configure(config):
    # Debian's Dask 2022.12 on Tornado 6.2 warns of its own event loop use.
    config.addinivalue_line("filterwarnings",
                            "ignore:make_current is deprecated"
                            ":DeprecationWarning")
