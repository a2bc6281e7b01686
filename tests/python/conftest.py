"""Shared fixtures: the project root, the release binary and the clips to check."""

import pathlib
import subprocess

import bvhio
import numpy as np
import pytest

ROOT = pathlib.Path(__file__).resolve().parents[2]
SINMDM = ROOT / "target" / "release" / "sinmdm"


def clips():
    """The shipped clips, plus every clip of the shared data folder beside the checkout."""
    shipped = sorted((ROOT / "tests" / "data" / "bvh").glob("*.bvh"))
    names = {p.name for p in shipped}
    shared = sorted((ROOT.parent / "shared" / "data" / "bvh").glob("*.bvh"))
    return shipped + [p for p in shared if p.name not in names]


@pytest.fixture(scope="session")
def sinmdm():
    """Runs the release `sinmdm` binary and returns its standard output."""
    if not SINMDM.exists():
        subprocess.run(["cargo", "build", "--release", "-p", "sinmdm"], cwd=ROOT, check=True)

    def run(*args):
        done = subprocess.run([str(SINMDM), *map(str, args)], capture_output=True, text=True)
        assert done.returncode == 0, done.stderr
        return done.stdout

    return run


def bvhio_joint_positions(path):
    """Global joint positions [frames, joints, 3] and joint names, as bvhio computes them."""
    root = bvhio.readAsHierarchy(str(path))
    layout = root.layout()
    frames = []
    for frame in range(len(root.Keyframes)):
        root.loadPose(frame)
        frames.append([list(joint.PositionWorld) for joint, _, _ in layout])
    return np.asarray(frames, dtype=np.float64), [joint.Name for joint, _, _ in layout]
