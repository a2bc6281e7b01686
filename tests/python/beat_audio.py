"""Music with exactly known beats, for the beat tracker's tests: click tracks, a drum pattern
built from CC0 one-shots, and tiled CC0 loops (tests/data/audio, see its ATTRIBUTION.md)."""

import pathlib
import wave

import numpy as np

AUDIO = pathlib.Path(__file__).resolve().parents[2] / "tests" / "data" / "audio"
RATE = 22050


def read_wav(path):
    """Mono float samples of a 16-bit WAV and its rate."""
    with wave.open(str(path), "rb") as w:
        assert w.getsampwidth() == 2, f"{path}: not 16-bit"
        data = np.frombuffer(w.readframes(w.getnframes()), dtype="<i2").astype(np.float64)
        data = data.reshape(-1, w.getnchannels()).mean(axis=1) / 32768.0
        return data, w.getframerate()


def write_wav(path, samples, rate=RATE):
    """Writes mono samples in -1..1 as 16-bit WAV."""
    pcm = np.clip(np.round(np.asarray(samples) * 32767.0), -32768, 32767).astype("<i2")
    with wave.open(str(path), "wb") as w:
        w.setnchannels(1)
        w.setsampwidth(2)
        w.setframerate(rate)
        w.writeframes(pcm.tobytes())


def grid(bpm, first, seconds):
    """Beat times every 60/bpm s from `first`, before `seconds` less a quarter second."""
    step = 60.0 / bpm
    return np.arange(first, seconds - 0.25, step)


def mix(seconds, hits):
    """A track of `seconds` with each (time, sound, gain) added."""
    out = np.zeros(int(round(seconds * RATE)))
    for t, sound, gain in hits:
        start = int(round(t * RATE))
        piece = sound[: max(0, min(len(sound), len(out) - start))]
        out[start : start + len(piece)] += gain * piece
    return out


def click_sound():
    t = np.arange(int(0.02 * RATE)) / RATE
    return np.sin(2 * np.pi * 1000.0 * t) * np.exp(-t / 0.004)


def click_track(bpm, phase, noise, seconds=30.0, seed=0):
    """Clicks on every beat (the first at `phase` beats), with white noise of std `noise`."""
    beats = grid(bpm, 0.5 + phase * 60.0 / bpm, seconds)
    track = mix(seconds, [(t, click_sound(), 0.8) for t in beats])
    track += np.random.default_rng(seed).normal(0.0, noise, len(track))
    return track, beats


def drum_pattern(bpm, seconds=30.0, seed=0):
    """Kick on beats 1 and 3, snare on 2 and 4, closed hi-hat on every eighth note (softer),
    a little noise: a plain rock beat."""
    kick, _ = read_wav(AUDIO / "drum_heavy_kick.wav")
    snare, _ = read_wav(AUDIO / "drum_snare_hard.wav")
    hat, _ = read_wav(AUDIO / "drum_cymbal_closed.wav")
    beats = grid(bpm, 0.4, seconds)
    hits = []
    for k, t in enumerate(beats):
        hits.append((t, kick if k % 2 == 0 else snare, 0.7))
        hits.append((t, hat, 0.25))
        hits.append((t + 30.0 / bpm, hat, 0.2))
    track = mix(seconds, hits)
    track += np.random.default_rng(seed).normal(0.0, 0.003, len(track))
    return track, beats


def tiled_loop(name, bpm, beats_per_loop, times):
    """A loop repeated `times` times; its beats fall every 60/bpm s from 0."""
    loop, rate = read_wav(AUDIO / f"{name}.wav")
    assert rate == RATE
    # The loop's length is exactly its beats (to a sample): the tiles keep the grid.
    assert abs(len(loop) / RATE - beats_per_loop * 60.0 / bpm) < 2.0 / RATE, name
    track = np.tile(loop, times)
    seconds = len(track) / RATE
    return track, grid(bpm, 0.0, seconds)


def cases():
    """(name, samples, true beat times, true bpm) of every test piece."""
    out = []
    for bpm in (60, 90, 120, 128, 174):
        for k, phase in enumerate((0.0, 0.37, 0.71)):
            samples, beats = click_track(bpm, phase, noise=0.02, seed=k)
            out.append((f"click_{bpm}_{k}", samples, beats, float(bpm)))
    for bpm in (100, 128):
        samples, beats = drum_pattern(bpm)
        out.append((f"drums_{bpm}", samples, beats, float(bpm)))
    samples, beats = tiled_loop("loop_amen_full", 140.0, 16, 4)
    out.append(("amen_140", samples, beats, 140.0))
    samples, beats = tiled_loop("loop_breakbeat", 126.0, 4, 12)
    out.append(("breakbeat_126", samples, beats, 126.0))
    return out


def f_measure(reference, estimated, tolerance=0.07):
    """Beat F-measure: each reference beat matches at most one estimate within `tolerance`."""
    estimated = list(estimated)
    used = [False] * len(estimated)
    hits = 0
    for r in reference:
        best = None
        for i, e in enumerate(estimated):
            if not used[i] and abs(e - r) <= tolerance and (best is None or abs(e - r) < abs(estimated[best] - r)):
                best = i
        if best is not None:
            used[best] = True
            hits += 1
    if hits == 0:
        return 0.0
    precision = hits / len(estimated)
    recall = hits / len(reference)
    return 2 * precision * recall / (precision + recall)


def median_error(reference, estimated):
    """Median distance from each reference beat to the nearest estimate, seconds."""
    estimated = np.asarray(estimated)
    return float(np.median([np.abs(estimated - r).min() for r in reference]))
