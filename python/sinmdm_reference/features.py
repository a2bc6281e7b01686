"""Features JSON files (runtime/src/features_file.rs)."""

import json

import numpy as np

FORMAT = "sinmdm-features"
VERSION = 1


def read_features(path):
    """Returns (array float32 [B, F, N], fps)."""
    with open(path) as f:
        doc = json.load(f)
    if doc.get("format") != FORMAT or doc.get("version") != VERSION:
        raise ValueError(f"{path}: not a {FORMAT} version {VERSION} file")
    return np.asarray(doc["samples"], dtype=np.float32), float(doc["fps"])


# The heading-relative root's rows, in order (runtime/src/motion/features/layout.rs).
HEADING_ROOT_ROWS = ("forward", "leftward", "turn", "Y")


def root_rows(layout):
    """How many feature rows the root has: one per axis, or four for a heading-relative root."""
    root = layout.get("root")
    if not root:
        return 0
    return len(HEADING_ROOT_ROWS) if root.get("heading") else len(root["axes"])


def column_names(layout):
    joints = layout["skeleton"]["joints"]
    names = []
    root = layout.get("root")
    if root:
        name = joints[root["joint"]]["name"]
        if root.get("heading"):
            names.extend(f"{name}.{row}" for row in HEADING_ROOT_ROWS)
        else:
            for axis in root["axes"]:
                names.append(f"{name}.Y" if axis == "Y" else f"{name}.d{axis}")
    for j in layout["rotation_joints"]:
        names.extend(f"{joints[j]['name']}.rot6d[{c}]" for c in range(6))
    for j, axis in layout["position_channels"]:
        names.append(f"{joints[j]['name']}.{axis}position")
    for j in layout["contact_joints"]:
        names.append(f"{joints[j]['name']}.contact")
    return names


def write_features(path, layout, features):
    """features float32 [B, F, N], unnormalised."""
    doc = {
        "format": FORMAT,
        "version": VERSION,
        "fps": layout["fps"],
        "columns": column_names(layout),
        "samples": np.asarray(features, dtype=np.float32).tolist(),
    }
    with open(path, "w") as f:
        json.dump(doc, f)
