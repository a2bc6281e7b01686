"""The beat tracker (`sinmdm beats`) against exact ground truth and against librosa 0.11's
dynamic-programming tracker, on music with known beats (beat_audio.py): click tracks at five
tempos and three phases under noise, a drum pattern from CC0 one-shots, and tiled CC0 loops."""

import json

import librosa
import numpy as np
import pytest

import beat_audio

TEMPO_TOLERANCE = 0.02
F_TOLERANCE_SECONDS = 0.07


@pytest.fixture(scope="module")
def tracked(tmp_path_factory, sinmdm):
    """Every case's truth, the tracker's beats and librosa's beats."""
    work = tmp_path_factory.mktemp("beats")
    out = {}
    for name, samples, truth, bpm in beat_audio.cases():
        wav = work / f"{name}.wav"
        beat_audio.write_wav(wav, samples)
        report = work / f"{name}.json"
        sinmdm("beats", wav, "--json", report)
        ours = json.loads(report.read_text())
        y, rate = beat_audio.read_wav(wav)
        _, theirs = librosa.beat.beat_track(y=y.astype(np.float32), sr=rate, units="time")
        out[name] = {"truth": truth, "bpm": bpm, "ours": ours, "librosa": np.asarray(theirs)}
    return out


def test_tempo_and_beats_match_the_ground_truth(tracked):
    failures = []
    for name, case in sorted(tracked.items()):
        ours = case["ours"]
        tempo_error = abs(ours["bpm"] - case["bpm"]) / case["bpm"]
        f = beat_audio.f_measure(case["truth"], ours["times"], F_TOLERANCE_SECONDS)
        median = beat_audio.median_error(case["truth"], ours["times"])
        print(f"{name}: {ours['bpm']:.2f} BPM (true {case['bpm']}), F {f:.3f}, median error "
              f"{median * 1000:.1f} ms, confidence {ours['confidence']:.2f}")
        # A double or half tempo is a miss: 2 % is far tighter than a factor of 2.
        if tempo_error > TEMPO_TOLERANCE or f < 0.9 or median > 0.030:
            failures.append(f"{name}: {ours['bpm']:.2f} BPM, F {f:.3f}, median {median * 1000:.1f} ms")
    assert not failures, failures


def test_the_tracker_agrees_with_librosa_where_librosa_finds_the_beat(tracked):
    """Agreement F >= 0.9 with librosa on every piece librosa itself tracks (its F against the
    truth >= 0.9). On the tiled breakbeat loops librosa settles on two thirds of the tempo (a
    known weakness of a prior around 120 BPM on syncopated breaks); those are listed, and the
    test above holds our tracker to the truth there."""
    agreed, librosa_misses, failures = 0, [], []
    for name, case in sorted(tracked.items()):
        theirs = case["librosa"]
        librosa_f = beat_audio.f_measure(case["truth"], theirs, F_TOLERANCE_SECONDS)
        if librosa_f < 0.9:
            librosa_misses.append(f"{name} (librosa F {librosa_f:.2f})")
            continue
        f = beat_audio.f_measure(theirs, case["ours"]["times"], F_TOLERANCE_SECONDS)
        print(f"{name}: agreement F {f:.3f}")
        agreed += 1
        if f < 0.9:
            failures.append(f"{name}: agreement F {f:.3f}")
    print("librosa misses:", librosa_misses)
    assert not failures, failures
    # Every click track and drum pattern is one librosa tracks: the comparison is not vacuous.
    assert agreed >= 17, f"librosa tracked only {agreed} pieces: {librosa_misses}"


def test_a_click_track_has_its_clicks_on_the_beats(tmp_path, sinmdm):
    samples, truth = beat_audio.click_track(120, 0.0, noise=0.01, seconds=12.0)
    wav = tmp_path / "song.wav"
    beat_audio.write_wav(wav, samples)
    click = tmp_path / "click.wav"
    report = tmp_path / "beats.json"
    sinmdm("beats", wav, "--click", click, "--json", report)
    beats = json.loads(report.read_text())["times"]
    clicked, rate = beat_audio.read_wav(click)
    assert len(clicked) == len(samples)
    # The added clicks: the click track less the song at half level.
    added = clicked - 0.5 * samples
    for t in beats:
        i = int(round(t * rate))
        assert np.abs(added[i : i + int(0.01 * rate)]).max() > 0.2, f"no click at {t:.3f} s"
    quiet = np.ones(len(added), dtype=bool)
    for t in beats:
        i = int(round(t * rate))
        quiet[max(i - 5, 0) : i + int(0.04 * rate)] = False
    assert np.abs(added[quiet]).max() < 0.01


def test_kinematic_beats_of_a_dance_clip(sinmdm, tmp_path):
    """The Rokoko dance clip's kinematic beats: speed minima of the smoothed mean joint speed,
    checked against a numpy computation from bvhio's joint positions."""
    from conftest import ROOT, bvhio_joint_positions

    clip = ROOT / "tests" / "data" / "bvh" / "human_dance_rokoko_jesse.bvh"
    report = tmp_path / "motion.json"
    sinmdm("beats", "--motion", clip, "--json", report)
    ours = json.loads(report.read_text())
    positions, _ = bvhio_joint_positions(clip)
    fps = ours["fps"]
    n = len(positions)
    idx = np.arange(n)
    a, b = np.maximum(idx - 1, 0), np.minimum(idx + 1, n - 1)
    speed = np.linalg.norm(positions[b] - positions[a], axis=2).mean(axis=1) / ((b - a) / fps)
    sigma = fps / 12.0
    reach = int(np.ceil(4 * sigma))
    kernel = np.exp(-0.5 * (np.arange(-reach, reach + 1) / sigma) ** 2)
    padded = np.pad(speed, reach, mode="symmetric")
    smooth = np.convolve(padded, kernel / kernel.sum(), mode="valid")
    minima = [t for t in range(1, n - 1) if smooth[t] < smooth[t - 1] and smooth[t] <= smooth[t + 1]]
    assert ours["minima"] == minima
    # The beats on the dance's beat are some of the minima.
    assert set(ours["frames"]) <= set(minima) and len(ours["frames"]) >= 8
    assert len(minima) > 10
