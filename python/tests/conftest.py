"""Shared fixtures: the CLI binary and the shared meshes (set by CTest)."""
import os
import subprocess

import pytest

CLI = os.environ.get("BSPRT_CLI", "bsprt")
SCENES = os.environ.get("BSPRT_SCENES_DIR", os.path.join(os.path.dirname(__file__), "../../../shared/scenes"))


def cli(*args):
    """Runs `bsprt ARGS`; returns its output, raising with it when it fails."""
    r = subprocess.run([CLI, *map(str, args)], capture_output=True, text=True)
    assert r.returncode == 0, f"bsprt {' '.join(map(str, args))} failed:\n{r.stdout}{r.stderr}"
    return r.stdout + r.stderr


@pytest.fixture(scope="session")
def scenes():
    return SCENES


@pytest.fixture(scope="session")
def suzanne(scenes):
    return os.path.join(scenes, "suzanne.obj")
