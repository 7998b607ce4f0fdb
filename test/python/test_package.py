"""``pip install .`` in a fresh virtual environment installs ``pre`` and ``post`` and
their console scripts, and they work from any directory (issue 18, item 7).

The environment sees the system's packages (numpy, h5py, ...: nothing is downloaded)
and the project is installed with ``--no-deps --no-build-isolation`` from a copy of
its Python sources, so the test neither touches the checkout nor needs the network.
Skipped only when no virtual environment can be created here."""
from __future__ import annotations

import os
import shutil
import subprocess
import sys
import venv
from pathlib import Path

import pytest

from conftest import REPO


def _copy_sources(dest: Path) -> None:
    dest.mkdir()
    for name in ("pyproject.toml", "README.md"):
        shutil.copy(REPO / name, dest / name)
    for pkg in ("pre", "post"):
        shutil.copytree(REPO / pkg, dest / pkg, ignore=shutil.ignore_patterns("__pycache__", "tests"))


def test_pip_install_and_run_from_elsewhere(tmp_path: Path) -> None:
    env_dir = tmp_path / "venv"
    try:
        venv.create(env_dir, system_site_packages=True, with_pip=True)
    except Exception as err:  # no ensurepip, no permission, ...
        pytest.skip(f"cannot create a virtual environment: {err}")
    python = env_dir / "bin" / "python"
    if not python.exists():
        pytest.skip("the virtual environment has no python")
    # (a PYTHONPATH naming a checkout would put it before the installed copy)
    env = {k: v for k, v in os.environ.items() if k != "PYTHONPATH"}
    src = tmp_path / "src"
    _copy_sources(src)
    install = subprocess.run([str(python), "-m", "pip", "install", "-q", "--no-deps",
                              "--no-build-isolation", str(src)], capture_output=True, text=True,
                             timeout=300, env=env)
    assert install.returncode == 0, install.stdout + install.stderr
    elsewhere = tmp_path / "elsewhere"
    elsewhere.mkdir()
    for args in (["-m", "post", "--help"], ["-m", "pre", "--help"]):
        res = subprocess.run([str(python), *args], capture_output=True, text=True, cwd=elsewhere,
                             timeout=120, env=env)
        assert res.returncode == 0, res.stderr
        assert "usage:" in res.stdout
    where = subprocess.run([str(python), "-c", "import post, pre; print(post.__file__, pre.__file__)"],
                           capture_output=True, text=True, cwd=elsewhere, timeout=60, env=env)
    assert where.stdout.count(str(env_dir)) == 2, where.stdout  # the installed copy, not the checkout
    for script in ("voiga-post", "voiga-pre"):
        res = subprocess.run([str(env_dir / "bin" / script), "--help"], capture_output=True,
                             text=True, cwd=elsewhere, timeout=120, env=env)
        assert res.returncode == 0 and "usage:" in res.stdout, res.stderr
