"""Leave-one-out judgement of the rule that reads the clip (train/src/choose/clip_rule/).

The rule's family, as the trainer ships it: a clip whose own intra diversity is under a threshold
T is calm and its steps are chosen by its own step ladder (nothing chosen on other clips); any
other clip is varied and trains a setting chosen for its feet: V2 on two feet or fewer, V4 on
three or more. For every clip H in turn, T, V2 and V4 are chosen on the other clips alone (the
most clips meeting every goal; ties go to the smaller total shortfall, then to the more varied
samples (the summed global diversity; `--tie-break margin` puts the summed margin of the clips
that meet every goal, each its nearest goal's, in its place), then to the threshold in the widest
gap between clips),
and H is judged with what was chosen. The script prints that table, the one with the rule chosen
on all the clips, and every measured cell.

The clips judged are those the default trains: each at the default's frame rate (data.fps 30). A
row whose name ends in `_60fps` is the same motion learned at its own frame rate, which only the
`--fps clip` override asks for: it is reported in a table of its own, with the rule chosen on all
the default's clips, and does not take part in the choice. `--with-other-rates` judges those rows
too, as the protocol did before (the same motion at another rate is then left out with H: it is
not another clip).

Goals (the adaptive-default issue): coverage >= 95; global diversity >= 1.2 where the clip's own
intra diversity is at least 0.7, else a mean longest verbatim run of at most 1 s; jitter at most
1.5x the clip's; training within 10 minutes on 2 cores (the trainer's wall time, where known).

The cells are the measured ones, kept in lab/scripts/measured_settings.csv (one row per clip and
setting: `sinmdm eval` of the trained model, 20 samples of twice the clip, seed 0, raw feet;
`where` names the section of lab/EXPERIMENTS.md that gives the run). Settings: `ladder`
(the step ladder's choice, its time including the ladder's), `d17k` (window 3, dropout 0.2,
17 000 steps: the default before the rule), `wKdNN` (window K, dropout 0.NN, 17 000 steps),
`wKcCsNk` (window K, C channels, N 000 steps, dropout 0.2), `wKcCdNNsNk` (the same with dropout
0.NN). A clip with no cell for a setting
misses every goal with it. A varied clip placed under T climbs the ladder first, whose
1 000-step rung does not cover it (measured on the CMU walk, the hop and the dog walk), and
trains its varied setting a minute later (LADDER_MINUTES).

Usage: python3 lab/scripts/leave_one_out.py [--tie-break diversity|margin] [--with-other-rates]
                                             [measured_settings.csv]"""

import csv
import math
import pathlib
import sys

HERE = pathlib.Path(__file__).resolve().parent
RATE_SUFFIXES = ("_60fps",)
MANY_FEET = 3
LADDER_MINUTES = 1.0


def load(path):
    cells, feet, intra = {}, {}, {}
    with open(path, newline="") as f:
        for r in csv.DictReader(f):
            name = r["clip"]
            feet[name] = int(r["feet"])
            cells[(name, r["setting"])] = {
                "coverage": float(r["coverage"]), "diversity": float(r["global_diversity"]),
                "intra": float(r["clip_intra"]), "replay": float(r["replay_s"]),
                "jitter": float(r["jitter_x"]),
                "minutes": float(r["train_min"]) if r["train_min"] else None}
            intra.setdefault(name, float(r["clip_intra"]))
    return cells, feet, intra


def at_another_rate(name):
    """Whether a row is a clip learned at its own frame rate, not the default's."""
    return any(name.endswith(suffix) for suffix in RATE_SUFFIXES)


def source(name):
    """The motion a clip name stands for: the same name at another frame rate is the same one."""
    for suffix in RATE_SUFFIXES:
        if name.endswith(suffix):
            return name[: -len(suffix)]
    return name


def goal_margins(s):
    """Each goal's signed margin (negative when missed), scaled so that one unit is about one goal."""
    m = {"coverage": (s["coverage"] - 95.0) / 5.0, "jitter": (1.5 - s["jitter"]) / 0.5}
    if s["intra"] >= 0.7:
        m["diversity"] = (s["diversity"] - 1.2) / 0.2
    else:
        m["replay"] = (1.0 - s["replay"]) / 0.5
    if s["minutes"] is not None:
        m["time"] = 10.0 - s["minutes"]
    return m


def shortfalls(s):
    """Each goal's shortfall (0 when met), in the units of `goal_margins`."""
    return {goal: max(0.0, -v) for goal, v in goal_margins(s).items()}


def margin(s):
    """The nearest goal's margin: how far a cell that meets every goal is from missing one."""
    return min(goal_margins(s).values())


def judge(s):
    """(every goal met, total shortfall); a cell never measured misses every goal."""
    if s is None:
        return False, math.inf
    f = shortfalls(s)
    return all(v == 0.0 for v in f.values()), sum(f.values())


def trained(cells, feet, intra, name, rule):
    """The setting `rule` (T, V2, V4) trains `name` with, and its cell."""
    threshold, v2, v4 = rule
    varied = v4 if feet[name] >= MANY_FEET else v2
    if intra[name] < threshold:
        ladder = cells.get((name, "ladder"))
        if ladder is not None:
            return "ladder", ladder
        cell = cells.get((name, varied))
        if cell is not None and cell["minutes"] is not None:
            cell = dict(cell, minutes=cell["minutes"] + LADDER_MINUTES)
        return f"ladder, then {varied}", cell
    return varied, cells.get((name, varied))


def choose(cells, feet, intra, train, tie_break="diversity"):
    settings = sorted({s for (_, s) in cells} - {"ladder"})
    values = sorted(intra[n] for n in train)
    cuts = [(values[0] - 0.05, 0.05)] + [
        ((a + b) / 2, b - a) for a, b in zip(values, values[1:])] + [(values[-1] + 0.05, 0.05)]
    best = None
    for threshold, gap in cuts:
        for v2 in settings:
            for v4 in settings:
                rule = (threshold, v2, v4)
                met, short, diversity, margins = 0, 0.0, 0.0, 0.0
                for n in train:
                    _, cell = trained(cells, feet, intra, n, rule)
                    ok, s = judge(cell)
                    met += ok
                    short += s
                    diversity += cell["diversity"] if cell else 0.0
                    margins += margin(cell) if ok else 0.0
                third = margins if tie_break == "margin" else diversity
                key = (met, -short, third, gap)
                if best is None or key > best[0]:
                    best = (key, rule)
    return best[1]


def row(name, label, cell):
    if cell is None:
        return f"| {name} | {label} | not measured | | | | | | - |"
    ok, _ = judge(cell)
    t = "" if cell["minutes"] is None else f"{cell['minutes']:.1f}"
    return (f"| {name} | {label} | {cell['coverage']:.1f} | {cell['diversity']:.3f} "
            f"| {cell['intra']:.3f} | {cell['replay']:.2f} | {cell['jitter']:.2f} | {t} "
            f"| {'met' if ok else '-'} |")


def main():
    args = sys.argv[1:]
    tie_break = "diversity"
    if "--tie-break" in args:
        i = args.index("--tie-break")
        tie_break = args[i + 1] if i + 1 < len(args) else ""
        del args[i:i + 2]
        if tie_break not in ("margin", "diversity"):
            sys.exit("--tie-break takes margin or diversity")
    with_other_rates = "--with-other-rates" in args
    args = [a for a in args if a != "--with-other-rates"]
    path = args[0] if args else HERE / "measured_settings.csv"
    cells, feet, intra = load(path)
    clips = sorted(n for n in intra if with_other_rates or not at_another_rate(n))
    other_rates = sorted(n for n in intra if n not in clips)
    header = ("| clip | chosen on the others | coverage | global diversity | clip intra | replay s "
              "| jitter x clip | train min | goals |\n|---|---|---|---|---|---|---|---|---|")
    print("Judged: each clip with the rule chosen on the other clips"
          + (" (not on the same motion at another frame rate)" if with_other_rates else "")
          + "\n")
    print(header)
    met = 0
    for held in clips:
        rule = choose(cells, feet, intra, [n for n in clips if source(n) != source(held)], tie_break)
        setting, cell = trained(cells, feet, intra, held, rule)
        met += judge(cell)[0]
        print(row(held, f"T {rule[0]:.3f}, V2 {rule[1]}, V4 {rule[2]}: {setting}", cell))
    print(f"\n{met} of {len(clips)} clips meet every goal on clips the rule was not chosen on.\n")

    def table(names, rule):
        """Prints each clip's row with the setting `rule` trains it with; the count that met."""
        met = 0
        for name in names:
            setting, cell = trained(cells, feet, intra, name, rule)
            met += judge(cell)[0]
            print(row(name, setting, cell))
        return met

    rule = choose(cells, feet, intra, clips, tie_break)
    print(f"Chosen on all {len(clips)}: T {rule[0]:.3f}, V2 {rule[1]}, V4 {rule[2]}\n")
    print(header)
    met = table(clips, rule)
    print(f"\n{met} of {len(clips)} clips meet every goal with the rule chosen on all.\n")
    if other_rates:
        print("At the clip's own frame rate (`--fps clip`, an override the default does not make), "
              f"with the rule chosen on all {len(clips)}:\n")
        print(header.replace("chosen on the others", "setting"))
        met = table(other_rates, rule)
        print(f"\n{met} of {len(other_rates)} meet every goal.\n")

    settings = sorted({s for (_, s) in cells})
    print("Every setting measured (coverage / global diversity / replay / jitter; - where not):\n")
    print("| clip (feet, intra) | " + " | ".join(settings) + " |")
    print("|---|" + "---|" * len(settings))
    for name in clips + other_rates:
        out = []
        for st in settings:
            c = cells.get((name, st))
            out.append("-" if c is None else
                       f"{c['coverage']:.1f} / {c['diversity']:.2f} / {c['replay']:.2f} s / "
                       f"{c['jitter']:.2f}x{' ok' if judge(c)[0] else ''}")
        print(f"| {name} ({feet[name]}, {intra[name]:.3f}) | " + " | ".join(out) + " |")


if __name__ == "__main__":
    main()
