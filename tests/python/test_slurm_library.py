"""A motion library as a Slurm job array on a real single-node Slurm started by
tests/cluster/slurm_library.sh (4 clips, 2 at a time; a task killed and resumed; a second
submission that trains nothing; a changed clip retrained alone; a failed clip reported)."""

import subprocess

import pytest

from conftest import ROOT


def test_a_library_runs_as_a_slurm_array():
    # The script makes (and after a success removes) its own folder in /tmp: munged needs one
    # that every user can reach, which pytest's tmp_path is not.
    done = subprocess.run(["bash", str(ROOT / "tests" / "cluster" / "slurm_library.sh")],
                          capture_output=True, text=True, timeout=900)
    if done.returncode == 0 and done.stdout.startswith("SKIP"):
        pytest.skip(done.stdout.strip())
    assert done.returncode == 0, done.stdout[-3000:] + done.stderr[-3000:]
    for check in ["1. three models", "2. the killed task resumed", "3. a second submission trained nothing",
                  "4. changing one clip retrained exactly that one", "5. a failed clip", "all checks passed"]:
        assert check in done.stdout, done.stdout
