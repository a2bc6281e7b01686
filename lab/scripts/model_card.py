"""Writes a shipped model's card (onnx-models/NAME.md) from its training run and `sinmdm eval`.

Usage (from the repository root, after training with the default configuration):
    python3 lab/scripts/model_card.py NAME CLIP.bvh RUN_DIR
    python3 lab/scripts/model_card.py NAME CLIP.bvh    # the same model, only its evaluation anew

It copies nothing: put the run's model at onnx-models/NAME.onnx first. The card's clip line and
its hand-written sections (those before "## Evaluation") are kept from the card it replaces;
the evaluation is run anew (`target/release/sinmdm eval`, 20 samples of twice the clip's length,
default sampling, seed 0, and the same with all 1 000 steps). Without RUN_DIR (the model is
unchanged, the runtime or the scoring is not), everything before "## Evaluation" is kept as it
is.
"""

import json
import pathlib
import re
import subprocess
import sys

import yaml


def eval_text(model: pathlib.Path, clip: str, extra: list[str]) -> str:
    out = subprocess.run(
        ["target/release/sinmdm", "eval", "-m", str(model), "--clip", clip, "--quiet", *extra],
        check=True,
        capture_output=True,
        text=True,
    ).stdout
    return "\n".join(line for line in out.splitlines() if not line.startswith("wrote ")).strip()


def grouped(n: int) -> str:
    """An integer with its thousands set apart by spaces (10 000)."""
    return f"{n:,}".replace(",", " ")


def kept_parts(old: str) -> tuple[str, str]:
    """The clip row and the hand-written sections (every one before "## Evaluation" but the step
    ladder's, which is written anew) of the old card."""
    clip = next((line for line in old.splitlines() if line.startswith("| clip |")), "")
    about = ""
    match = re.search(r"^## (?!Evaluation|Step ladder).*?(?=^## Evaluation)", old, flags=re.S | re.M)
    if match:
        about = match.group(0).strip() + "\n\n"
    return clip, about


def frames_seen(t: dict, state: dict) -> str:
    """What a step saw of the clip: the batch the run recorded in its state.json."""
    batch = state.get("batch")
    if batch is None:
        sys.exit("the run's state.json does not record its batch (a run saved before it was kept)")
    items, window = batch["items"], batch["window"]
    plural = "s" if items > 1 else ""
    if window is not None and window < state["clip"]["frames"]:
        seen = f"{items} random window{plural} of {window} frames"
    else:
        seen = f"{items} item{plural} of the clip"
    if t.get("frames_per_step"):
        return f"{t['frames_per_step']} frames per step ({seen})"
    return f"batch of {seen}"


def ladder_rungs(run: pathlib.Path) -> list[dict]:
    """The step ladder's rungs of a calm clip's run (step_ladder/steps-N*/check.json), those at
    the configuration's learning rate first, fewest steps first; none for a varied clip's run."""
    checks = [json.loads(p.read_text()) for p in (run / "step_ladder").glob("steps-*/check.json")]
    return sorted(checks, key=lambda c: (c.get("learning_rate") is not None, c["steps"]))


def rung_label(rung: dict) -> str:
    """A rung as the card names it: its steps, and its learning rate where it has its own."""
    rate = rung.get("learning_rate")
    return f"{rung['steps']}" if rate is None else f"{rung['steps']} at learning rate {rate:g}"


def kinematic_cells(rung: dict) -> str:
    """A rung's kinematic figures as three table cells (blank for a rung scored before the
    check measured them)."""
    k = rung.get("kinematics")
    if not k:
        return " | | "
    p25, p50, p90 = k["speed_ratios"]
    return (
        f"{100 * k['still_share']:.1f} ({100 * rung['clip_still_share']:.1f}) | "
        f"{p25:.2f} / {p50:.2f} / {p90:.2f} | "
        f"{k['speed_distance']:.2f} / {k['acceleration_distance']:.2f}"
    )


def ladder_section(rungs: list[dict], chosen: int, chosen_rate: float, default_rate: float) -> list[str]:
    """The card's table of the step ladder: each rung's samples as the trainer scored them; the
    chosen one trained `chosen` steps at `chosen_rate` (a rung without its own rate has the
    configuration's, `default_rate`)."""
    if not rungs:
        return []
    picked = [r for r in rungs if r["steps"] == chosen and (r.get("learning_rate") or default_rate) == chosen_rate]
    label = rung_label(picked[0]) if picked else f"{chosen}-step"
    text = [
        "## Step ladder",
        "",
        "The clip is calm, so the trainer chose its steps by the samples of short runs (the step "
        "ladder: lab/EXPERIMENTS.md, *The step ladder*; 20 samples of twice the clip, "
        f"seed 1, default sampling). It trained the {label} rung:",
        "",
        "| rung | coverage | replay (s) | jitter x clip | global diversity | still % (clip) "
        "| speed p25 / p50 / p90 x clip | speed / acc. distance | train + check (s) |",
        "|---|---|---|---|---|---|---|---|---|",
    ]
    for r in rungs:
        mark = " (chosen)" if any(r is p for p in picked) else ""
        text.append(
            f"| {rung_label(r)}{mark} | {r['coverage']:.1f} | {r['replay_seconds']:.2f} | "
            f"{r['jitter_ratio']:.2f} | {r['global_diversity']:.3f} | {kinematic_cells(r)} | "
            f"{r['train_seconds']:.0f} + {r['check_seconds']:.0f} |"
        )
    return text + [""]


def evaluation(name: str, clip: str, model: pathlib.Path) -> list[str]:
    """The card's evaluation section, run anew."""
    return [
        "## Evaluation",
        "",
        f"`sinmdm eval -m onnx-models/{name}.onnx --clip {clip}` (20 samples of twice the clip's "
        "length, default sampling, seed 0): the samples as the network made them, then with their "
        "feet planted (the default output; coverage and diversity measured on the planted motion "
        "re-encoded, beside the raw motion scored the same way), then the feet and smoothness "
        "figures of SPEC section 9.",
        "",
        eval_text(model, clip, []),
        "",
        "With all 1 000 steps (`--steps all`):",
        "",
        eval_text(model, clip, ["--steps", "all"]),
        "",
    ]


def main() -> None:
    if len(sys.argv) not in (3, 4):
        sys.exit(__doc__)
    name, clip = sys.argv[1], sys.argv[2]
    card = pathlib.Path("onnx-models") / f"{name}.md"
    model = pathlib.Path("onnx-models") / f"{name}.onnx"
    if len(sys.argv) == 3:
        old = card.read_text()
        head = old[: old.index("## Evaluation")] if "## Evaluation" in old else old
        card.write_text(head.rstrip() + "\n\n" + "\n".join(evaluation(name, clip, model)))
        print(f"wrote {card} (evaluation only)")
        return
    run = pathlib.Path(sys.argv[3])
    clip_row, about = kept_parts(card.read_text() if card.exists() else "")
    latest = (run / "latest").read_text().strip()
    state = json.loads((run / latest / "state.json").read_text())
    config = state["config"]
    m, t, d = config["model"], config["training"], config["data"]
    layout = state["clip"]["layout"]
    contacts = len(layout["contact_joints"])
    joints = len(layout["skeleton"]["joints"])
    fps = "the clip's own rate" if d["fps"] is None else f"{d['fps']:g} fps"
    # A run's configuration without data.std_floor was trained under the floor before it.
    floor = d.get("std_floor", 0.001)
    default_config = yaml.safe_load(pathlib.Path("configs/default.yaml").read_text())
    default_floor = default_config["data"]["std_floor"]
    default_rate = default_config["training"]["learning_rate"]
    config_row = (
        f"the default (`configs/default.yaml`: C {m['channels']}, {m['heads']} heads, window "
        f"{m['window']}, dropout {m['dropout']}, cosine learning rate "
        f"from {t['learning_rate']:g} after {t['warmup_steps']} warm-up steps, weight average "
        f"{t.get('ema_decay')}, {frames_seen(t, state)}, {fps}, feature spread floor {floor:g}, "
        f"seed {t['seed']}; the step count (and, for a rung of the step ladder's faster arm, the "
        "learning rate), window, dropout and channels as the default's `from_clip` rule chose "
        "them from the clip)"
    )
    if d.get("root_layout", "world") != "world":
        config_row += f", with the {d['root_layout']} root layout"
    size_mb = model.stat().st_size / 1e6
    extra_args = " --fps clip" if d["fps"] is None else ""
    if d.get("root_layout", "world") != "world":
        extra_args += f" --root-layout {d['root_layout']}"
    if floor != default_floor:
        extra_args += f" --std-floor {floor:g}"
    rungs = ladder_rungs(run)
    elapsed = state["elapsed_seconds"]
    ladder_seconds = sum(r["train_seconds"] + r["check_seconds"] for r in rungs)
    if rungs:
        total = elapsed + ladder_seconds
        timing = (
            f"{total:.0f} s ({total / 60:.1f} min: the step ladder's {len(rungs)} rungs "
            f"{ladder_seconds:.0f} s, then the run {elapsed:.0f} s)"
        )
    else:
        timing = f"{elapsed:.0f} s ({elapsed / 60:.1f} min)"
    rows = [
        ("clip", clip_row.split("|")[2].strip() if clip_row else f"`{clip}`"),
        ("config", config_row),
        ("steps", grouped(state["step"])),
        (
            "training time",
            f"{timing} on a 2-core AMD EPYC virtual machine, no other training running",
        ),
        ("loss", f"last step {state['loss']:.4f}, mean of the last {min(100, state['step'])} steps {state['recent_loss']:.4f}"),
        (
            "size",
            f"{size_mb:.1f} MB, {grouped(state['parameters'])} parameters, F {state['features']} "
            f"({joints} joints, {contacts} contacts)",
        ),
    ]
    text = [f"# {name}.onnx", "", "| | |", "|---|---|"]
    text += [f"| {k} | {v} |" for k, v in rows]
    text += [
        "",
        f"Made with `sinmdm-train {clip} --out runs/{name}{extra_args} --export onnx-models/{name}.onnx`.",
        "",
        *ladder_section(rungs, state["step"], t["learning_rate"], default_rate),
        *([about.rstrip(), ""] if about.strip() else []),
        *evaluation(name, clip, model),
    ]
    card.write_text("\n".join(text))
    print(f"wrote {card}")


if __name__ == "__main__":
    main()
