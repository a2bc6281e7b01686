"""Makes tests/data/audio from Debian's sonic-pi-samples (CC0 one-shots and loops): each file
mixed to mono, resampled to 22 050 Hz and written as 16-bit WAV. Run once by a developer; the
outputs are committed with their attribution (tests/data/audio/ATTRIBUTION.md).

    apt-get install sonic-pi-samples && .venv/bin/python lab/scripts/make_audio_fixtures.py
"""

import pathlib

import librosa
import numpy as np
import soundfile

SAMPLES = pathlib.Path("/usr/share/sonic-pi/samples")
OUT = pathlib.Path(__file__).resolve().parents[2] / "tests" / "data" / "audio"
NAMES = ["drum_heavy_kick", "drum_snare_hard", "drum_cymbal_closed", "loop_amen_full",
         "loop_breakbeat"]
RATE = 22050


def main():
    OUT.mkdir(parents=True, exist_ok=True)
    for name in NAMES:
        audio, rate = soundfile.read(SAMPLES / f"{name}.flac", always_2d=True)
        mono = audio.mean(axis=1)
        mono = librosa.resample(mono, orig_sr=rate, target_sr=RATE)
        peak = np.abs(mono).max()
        if peak > 1.0:
            mono = mono / peak
        soundfile.write(OUT / f"{name}.wav", mono, RATE, subtype="PCM_16")
        print(f"{name}: {len(mono) / RATE:.3f} s")


if __name__ == "__main__":
    main()
