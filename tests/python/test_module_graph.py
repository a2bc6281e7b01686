"""The shape of the tree. No module cycle inside any crate: within each crate of the workspace
and of `bindings/`, sibling modules (children of the same parent) import one way. A module's
imports are its `crate::...` and `super::...` paths outside comments and test modules, each
resolved to the deepest module it names. And no Rust file, tests included, over
`MAX_FILE_LINES` lines: past that a file holds more than one concept."""

import re
import subprocess
import tomllib

import pytest

from conftest import ROOT

MAX_FILE_LINES = 550


def workspace_crates():
    """Every crate of the main workspace, and the bindings' own workspaces."""
    members = tomllib.loads((ROOT / "Cargo.toml").read_text())["workspace"]["members"]
    bindings = [str(p.parent.relative_to(ROOT)) for p in (ROOT / "bindings").glob("*/Cargo.toml")]
    return sorted(members + bindings)


CRATES = workspace_crates()


def module_of(src, path):
    parts = list(path.relative_to(src).with_suffix("").parts)
    if parts and parts[-1] in ("mod", "lib", "main"):
        parts = parts[:-1]
    return tuple(parts)


def imports(module, text):
    text = re.sub(r"#\[cfg\(test\)\]\s*mod tests \{.*", "", text, flags=re.S)
    text = re.sub(r"//[^\n]*", "", text)
    out = []
    for m in re.finditer(r"crate((?:::[a-z_0-9]+)+)(?:::\{([^}]*)\})?", text):
        base = tuple(m.group(1).strip(":").split("::"))
        out.append(base)
        for item in (m.group(2) or "").split(","):
            names = [x for x in item.strip().split(" as ")[0].split("::") if re.fullmatch(r"[a-z_0-9]+", x)]
            if names:
                out.append(base + tuple(names))
    for m in re.finditer(r"\b((?:super::)+)([a-z_0-9]+(?:::[a-z_0-9]+)*)", text):
        up = m.group(1).count("super::")
        out.append(module[:max(len(module) - up, 0)] + tuple(m.group(2).split("::")))
    return out


def sibling_cycles(crate):
    src = ROOT / crate / "src"
    files = {p: module_of(src, p) for p in src.rglob("*.rs") if "bin" not in p.relative_to(src).parts}
    known = {m[:i] for m in files.values() for i in range(len(m) + 1)}
    edges = {}
    for path, module in files.items():
        for target in imports(module, path.read_text()):
            target = target[:max(i for i in range(len(target) + 1) if target[:i] in known)]
            c = 0
            while c < min(len(module), len(target)) and module[c] == target[c]:
                c += 1
            if c < len(module) and c < len(target):
                edges.setdefault(module[:c + 1], set()).add(target[:c + 1])
    cycles = set()

    def walk(node, stack):
        for nxt in edges.get(node, ()):
            if nxt in stack:
                cycles.add(" -> ".join("::".join(m) for m in stack[stack.index(nxt):] + [nxt]))
            elif len(stack) < 16:
                walk(nxt, stack + [nxt])

    for node in list(edges):
        walk(node, [node])
    return sorted(cycles), sum(len(v) for v in edges.values())


@pytest.mark.parametrize("crate", CRATES)
def test_sibling_modules_import_one_way(crate):
    cycles, edges = sibling_cycles(crate)
    modules = [p for p in (ROOT / crate / "src").rglob("*.rs") if "bin" not in p.parts]
    assert edges > 0 or len(modules) < 4, f"{crate}: no imports seen; is the pattern still right?"
    assert not cycles, f"{crate} has module cycles:\n" + "\n".join(cycles)


# The training crate's wings, highest first: a module imports only wings ranked below its own
# (those ranked 0 may import each other; the sibling check above keeps them free of cycles).
TRAIN_WINGS = {"library_task": 5, "choose": 4, "export": 3, "run": 2, "clip": 1,
               "chosen": 0, "config": 0, "model": 0}


def wing_climbs(crate, wings):
    """Every import that climbs: (file, the wing it sits in, the wing it imports)."""
    src = ROOT / crate / "src"
    climbs = []
    for path in sorted(src.rglob("*.rs")):
        module = module_of(src, path)
        if not module or module[0] not in wings or "bin" in path.relative_to(src).parts:
            continue
        here = wings[module[0]]
        for target in imports(module, path.read_text()):
            there = wings.get(target[0]) if target else None
            if there is None or target[0] == module[0]:
                continue
            if there > here or (there == here and here > 0):
                climbs.append((str(path.relative_to(ROOT)), module[0], target[0]))
    return climbs


def test_the_training_wings_import_downward_only():
    """The policy (`choose`) sits above the run, the run above the clip: the trainer imports
    nothing from the rule that reads the clip."""
    src = ROOT / "train" / "src"
    assert all((src / wing).exists() or (src / f"{wing}.rs").exists() for wing in TRAIN_WINGS)
    climbs = wing_climbs("train", TRAIN_WINGS)
    assert not climbs, "imports that climb:\n" + "\n".join(f"  {f}: {a} -> {b}" for f, a, b in climbs)


def test_the_wing_check_sees_a_climb(tmp_path, monkeypatch):
    src = tmp_path / "demo" / "src"
    (src / "run").mkdir(parents=True)
    (src / "lib.rs").write_text("pub mod choose;\npub mod run;\n")
    (src / "choose.rs").write_text("use crate::run::Trainer;\n")
    (src / "run" / "mod.rs").write_text("use crate::choose::clip_rule::RuleChoice;\n")
    monkeypatch.setattr("test_module_graph.ROOT", tmp_path)
    assert wing_climbs("demo", {"choose": 2, "run": 1}) == [("demo/src/run/mod.rs", "run", "choose")]


def test_the_check_finds_a_cycle_when_there_is_one(tmp_path, monkeypatch):
    src = tmp_path / "demo" / "src"
    src.mkdir(parents=True)
    (src / "lib.rs").write_text("mod a;\nmod b;\n")
    (src / "a.rs").write_text("use crate::b::thing;\n")
    (src / "b.rs").write_text("use super::a::other; // a comment naming crate::c\n")
    monkeypatch.setattr("test_module_graph.ROOT", tmp_path)
    cycles, _ = sibling_cycles("demo")
    assert cycles and "a -> b -> a" in cycles[0] or "b -> a -> b" in cycles[0]


def test_every_crate_is_looked_at():
    for crate in ["runtime", "train", "capi", "beats", "library", "bindings/bevy"]:
        assert crate in CRATES


def test_no_rust_file_is_over_the_line_bound():
    tracked = subprocess.run(
        ["git", "ls-files", "*.rs"], cwd=ROOT, check=True, capture_output=True, text=True
    ).stdout.split()
    assert len(tracked) > 100, "git ls-files found too few Rust files; is this a checkout?"
    long = sorted(
        (n, path)
        for path in tracked
        if (n := len((ROOT / path).read_text().splitlines())) > MAX_FILE_LINES
    )
    assert not long, f"Rust files over {MAX_FILE_LINES} lines (split them by concept):\n" + "\n".join(
        f"  {path}: {n}" for n, path in reversed(long)
    )
