"""A motion library without a scheduler: `sinmdm-train --manifest` tasks run one after another
(what each array task does), and `sinmdm library` reads them back. Checks what a task promises
whatever runs it: a current model is not trained again, a killed task resumes from its
checkpoint, a changed configuration makes the model stale and retrains it, a clip that does not
parse fails with its error in the status, and the report and contact sheet cover the rest."""

import json
import os
import shutil
import signal
import subprocess
import time

from conftest import ROOT, SINMDM, TRAIN, tiny_config


def task(manifest, index, **kwargs):
    return subprocess.run([TRAIN, "--manifest", manifest, "--index", str(index)], capture_output=True,
                          text=True, **kwargs)


def test_tasks_are_idempotent_resumable_and_reported(tmp_path):
    shutil.copy(ROOT / "tests/data/bvh/human_walk_cmu_131_01.bvh", tmp_path / "walk.bvh")
    shutil.copy(ROOT / "tests/data/bvh/fox_survey_khronos.bvh", tmp_path / "fox.bvh")
    (tmp_path / "broken.bvh").write_text("HIERARCHY\nROOT\n")
    (tmp_path / "short.yaml").write_text(tiny_config(30))
    (tmp_path / "long.yaml").write_text(tiny_config(400).replace("checkpoint_every: 100", "checkpoint_every: 10"))
    manifest = tmp_path / "library.yaml"
    manifest.write_text("config: short.yaml\nsamples: 2\nclips:\n  - clip: walk.bvh\n"
                        "  - clip: fox.bvh\n    config: long.yaml\n  - clip: broken.bvh\n")
    out = tmp_path / "library"

    done = task(manifest, 0)
    assert done.returncode == 0, done.stderr
    assert "task 0: trained" in done.stderr
    for name in ["model.onnx", "card.md", "eval.json", "sample.bvh", "fingerprint"]:
        assert (out / "walk" / name).is_file(), name
    status = json.loads((out / "walk" / "status.json").read_text())
    assert status["state"] == "done" and status["steps"] == 30
    modified = (out / "walk" / "model.onnx").stat().st_mtime_ns
    again = task(manifest, 0)
    assert again.returncode == 0 and "up to date" in again.stderr, again.stderr
    assert (out / "walk" / "model.onnx").stat().st_mtime_ns == modified

    # Killed once it has a checkpoint, then run again: it resumes and its loss log goes on.
    running = subprocess.Popen([TRAIN, "--manifest", manifest, "--index", "1"], stderr=subprocess.DEVNULL)
    latest = out / "fox" / "run" / "latest"
    for _ in range(600):
        if latest.exists():
            break
        time.sleep(0.05)
    running.send_signal(signal.SIGKILL)
    running.wait()
    assert latest.exists() and not (out / "fox" / "model.onnx").exists()
    resumed = task(manifest, 1)
    assert resumed.returncode == 0 and "resumed and finished" in resumed.stderr, resumed.stderr
    steps = [int(line.split(",")[0]) for line in (out / "fox" / "run" / "loss.csv").read_text().splitlines()[1:]]
    assert steps == list(range(1, 401))

    failed = task(manifest, 2)
    assert failed.returncode != 0
    status = subprocess.run([SINMDM, "library", "status", "--manifest", manifest], capture_output=True, text=True)
    assert status.returncode == 0, status.stderr
    assert "broken                   failed: " in status.stdout and "broken.bvh" in status.stdout, status.stdout
    assert "3 clips: 2 done, 0 running, 1 failed, 0 stale, 0 pending" in status.stdout

    # A changed configuration makes the walk stale; its task retrains it.
    (tmp_path / "short.yaml").write_text(tiny_config(31))
    stale = subprocess.run([SINMDM, "library", "status", "--manifest", manifest], capture_output=True, text=True)
    assert "walk                     stale" in stale.stdout, stale.stdout
    retrained = task(manifest, 0)
    assert "task 0: trained" in retrained.stderr, retrained.stderr
    assert json.loads((out / "walk" / "status.json").read_text())["steps"] == 31

    report = subprocess.run([SINMDM, "library", "report", "--manifest", manifest, "-o", tmp_path / "report"],
                            capture_output=True, text=True)
    assert report.returncode == 0, report.stderr
    table = (tmp_path / "report" / "report.md").read_text()
    assert "| walk | done |" in table and "| fox | done |" in table and "| broken | failed |" in table
    rows = json.loads((tmp_path / "report" / "report.json").read_text())
    assert [r["standing"] for r in rows] == ["done", "done", "failed"]
    assert all(0 <= r["coverage"] <= 100 for r in rows[:2])
    assert (tmp_path / "report" / "contact_sheet.png").read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    assert os.path.getsize(tmp_path / "report" / "contact_sheet.png") > 1000


def test_a_task_killed_during_its_step_ladder_keeps_the_rungs_it_finished(tmp_path):
    # The fox is calm: with the rule asked for its steps, its task climbs the step ladder (the
    # tiny model's rungs train in seconds) before its run has any checkpoint.
    shutil.copy(ROOT / "tests/data/bvh/fox_survey_khronos.bvh", tmp_path / "fox.bvh")
    (tmp_path / "ladder.yaml").write_text(tiny_config(300) + "from_clip:\n  steps: true\n")
    manifest = tmp_path / "library.yaml"
    manifest.write_text("config: ladder.yaml\nsamples: 2\nclips:\n  - clip: fox.bvh\n")
    ladder = tmp_path / "library" / "fox" / "run" / "step_ladder"
    first = ladder / "steps-1000" / "check.json"

    running = subprocess.Popen([TRAIN, "--manifest", manifest, "--index", "0"], stderr=subprocess.DEVNULL)
    for _ in range(2400):
        if first.exists() or running.poll() is not None:
            break
        time.sleep(0.05)
    running.send_signal(signal.SIGKILL)
    running.wait()
    assert first.exists(), "the task ended or timed out before its first rung was scored"
    assert not (tmp_path / "library" / "fox" / "run" / "latest").exists(), "killed too late"
    scored = first.read_bytes()
    finished = sorted(p.parent.name for p in ladder.glob("steps-*/check.json"))

    again = task(manifest, 0)
    assert again.returncode == 0, again.stderr
    assert "task 0: trained" in again.stderr, again.stderr
    # The rungs finished before the kill were kept, not trained again (a rung trained again
    # would have written its scores anew, with its own training time).
    assert first.read_bytes() == scored
    assert all((ladder / name / "check.json").exists() for name in finished)
    status = json.loads((tmp_path / "library" / "fox" / "status.json").read_text())
    assert status["state"] == "done"
    # A rung of the ladder, or of its faster arm (1 000 or 3 000 steps at learning rate 1e-3).
    assert status["steps"] in (50, 75, 100, 150, 200, 250, 300, 400, 600, 1000, 3000), status
