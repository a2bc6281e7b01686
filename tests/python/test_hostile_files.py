"""Files a stranger could hand over, read by the command line under a memory cap: each gives a
clean error that names the file (exit status 1, no panic, no signal) quickly, and together they
never take 100 MB. The cases are those of the files-from-strangers report, plus deep nesting,
huge declared counts, long lines and an FBX array that declares gigabytes."""

import json
import resource
import struct
import subprocess
import sys
import time
import zlib

import pytest

from conftest import ROOT, SINMDM

# The address space each run may take (ulimit -v): far below what a runaway read would reach.
ADDRESS_SPACE = 512 << 20
# The resident memory each run stays under.
RESIDENT_LIMIT_KB = 100 * 1024


# Runs a command under the cap and writes its peak resident memory (KB) to the file named first:
# a process of its own, so that nothing else this test session started is counted.
MEASURED = f"""
import resource, subprocess, sys
cap = {ADDRESS_SPACE}
limit = lambda: resource.setrlimit(resource.RLIMIT_AS, (cap, cap))
done = subprocess.run(sys.argv[2:], preexec_fn=limit)
open(sys.argv[1], "w").write(str(resource.getrusage(resource.RUSAGE_CHILDREN).ru_maxrss))
sys.exit(done.returncode)
"""


def gltf(tmp_path, name, buffer, extra=None):
    document = {
        "asset": {"version": "2.0"},
        "buffers": [buffer],
        "bufferViews": [{"buffer": 0, "byteLength": buffer["byteLength"]}],
        "accessors": [{"bufferView": 0, "componentType": 5126, "count": 4, "type": "SCALAR"}],
        "nodes": [{"name": "Hips"}],
        "skins": [{"joints": [0]}],
    }
    document.update(extra or {})
    path = tmp_path / name
    path.write_text(json.dumps(document))
    return path


def fbx_bomb(path):
    """A binary FBX whose one Vertices array declares 2^28 doubles (2 GiB) in 30 bytes of zlib."""
    def node(name, props, children, start):
        plist = b"".join(props)
        offset = start + 13 + len(name) + len(plist)
        body = b""
        for child in children:
            bytes_ = child(offset + len(body))
            body += bytes_
        if children:
            body += b"\0" * 13
        end = start + 13 + len(name) + len(plist) + len(body)
        return struct.pack("<IIIB", end, len(props), len(plist), len(name)) + name + plist + body

    array = zlib.compress(b"\0" * 4096)
    vertices = lambda at: node(b"Vertices", [b"d" + struct.pack("<III", 1 << 28, 1, len(array)) + array], [], at)
    geometry = lambda at: node(b"Geometry", [b"L" + struct.pack("<q", 1), b"S" + struct.pack("<I", 4) + b"Mesh"],
                               [vertices], at)
    header = b"Kaydara FBX Binary  \x00\x1a\x00" + struct.pack("<I", 7400)
    path.write_bytes(header + node(b"Objects", [], [geometry], len(header)) + b"\0" * 13)
    return path


def cases(tmp_path):
    (tmp_path / "secret").mkdir()
    (tmp_path / "secret" / "hidden.bin").write_bytes(b"\0" * 16)
    (tmp_path / "clips").mkdir()
    small = tmp_path / "clips" / "data.bin"
    small.write_bytes(b"\0" * 16)
    deep = "HIERARCHY\nROOT j0\n{\nOFFSET 0 0 0\nCHANNELS 3 Zrotation Xrotation Yrotation\n"
    deep += "".join(f"JOINT j{i}\n{{\nOFFSET 0 1 0\nCHANNELS 3 Zrotation Xrotation Yrotation\n" for i in range(1, 200_000))
    deep += "}\n" * 200_000 + "MOTION\nFrames: 1\nFrame Time: 0.033\n0 0 0\n"
    (tmp_path / "deep.bvh").write_text(deep)
    frames = "HIERARCHY\nROOT Hips\n{\nOFFSET 0 0 0\nCHANNELS 3 Zrotation Xrotation Yrotation\n"
    frames += "End Site\n{\nOFFSET 0 1 0\n}\n}\nMOTION\nFrames: 99999999999\nFrame Time: 0.033\n0 0 0\n"
    (tmp_path / "frames.bvh").write_text(frames)
    one_frame = frames.replace("Frames: 99999999999", "Frames: 1")
    hierarchy, motion = one_frame.split("MOTION")
    long_offset = hierarchy.replace("OFFSET 0 1 0", "OFFSET " + "0 " * 5_000_000)
    (tmp_path / "long_offset.bvh").write_text(long_offset + "MOTION" + motion)
    long_frame = one_frame.removesuffix("0 0 0\n") + "0 " * 5_000_000 + "\n"
    (tmp_path / "long_frame.bvh").write_text(long_frame)
    wav = b"RIFF" + struct.pack("<I", 36 + 0x7FFFFFF0) + b"WAVEfmt " + struct.pack("<IHHIIHH", 16, 1, 1, 44100, 88200, 2, 16)
    (tmp_path / "huge.wav").write_bytes(wav + b"data" + struct.pack("<I", 0x7FFFFFF0) + b"\0" * 64)
    return [
        ("inspect", gltf(tmp_path, "dev_zero.gltf", {"uri": "/dev/zero", "byteLength": 95396})),
        ("inspect", gltf(tmp_path / "clips", "huge.gltf", {"uri": "data.bin", "byteLength": 8_000_000_000})),
        ("inspect", gltf(tmp_path / "clips", "outside.gltf", {"uri": "../secret/hidden.bin", "byteLength": 16})),
        ("inspect", gltf(tmp_path, "scheme.gltf", {"uri": "file:///etc/passwd", "byteLength": 16})),
        ("inspect", gltf(tmp_path / "clips", "count.gltf", {"uri": "data.bin", "byteLength": 16},
                         {"accessors": [{"bufferView": 0, "componentType": 5126, "count": 4_000_000_000,
                                         "type": "MAT4"}],
                          "animations": [{"samplers": [{"input": 0, "output": 0}],
                                          "channels": [{"sampler": 0,
                                                        "target": {"node": 0, "path": "rotation"}}]}]})),
        ("inspect", tmp_path / "deep.bvh"),
        ("inspect", tmp_path / "frames.bvh"),
        ("inspect", tmp_path / "long_offset.bvh"),
        ("inspect", tmp_path / "long_frame.bvh"),
        ("inspect", fbx_bomb(tmp_path / "bomb.fbx")),
        # Found by the glTF fuzz target: one key moved to 522 s in a 31 KB file.
        ("inspect", ROOT / "tests" / "data" / "gltf" / "fuzz_far_keys.glb"),
        ("beats", tmp_path / "huge.wav"),
    ]


def test_every_hostile_file_gets_a_clean_error_under_a_memory_cap(tmp_path, capsys):
    figures = []
    peak = tmp_path / "peak.txt"
    for command, path in cases(tmp_path):
        start = time.perf_counter()
        done = subprocess.run([sys.executable, "-c", MEASURED, str(peak), str(SINMDM), command, str(path)],
                              capture_output=True, text=True, timeout=60)
        resident = int(peak.read_text())
        figures.append((path.name, time.perf_counter() - start, resident))
        assert done.returncode == 1, (path.name, done.returncode, done.stderr[-2000:])
        assert "panicked" not in done.stderr, (path.name, done.stderr)
        assert done.stderr.startswith("error: ") and path.name in done.stderr, (path.name, done.stderr)
        assert resident < RESIDENT_LIMIT_KB, (path.name, f"{resident / 1024:.0f} MB")
    with capsys.disabled():
        print("\nhostile files (seconds, peak MB):",
              ", ".join(f"{n} {t:.2f} {r / 1024:.0f}" for n, t, r in figures))
