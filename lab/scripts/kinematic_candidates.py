"""The candidate table of "Motion that moves like the clip": one Markdown row per trained variant
(`sinmdm eval` JSON, 20 samples, seed 0, as lab/scripts/variant_runs.sh writes them) or ladder
rung (`step_ladder/steps-N/check.json`, seed 1, the ladder's own scores), with the kinematic
goals beside the others, and the bounds each row misses.

Usage: python3 lab/scripts/kinematic_candidates.py OUT_DIR [--rungs] [--planted]
  OUT_DIR   the runs' folder (out/variants by default in the lab's drivers)
  --rungs   also list every ladder rung of every *.ladder* run
  --planted score the samples with their feet planted (the default output: kinematics, coverage,
            diversity and jitter of the planted motion) instead of as the network made them
"""
import json
import pathlib
import sys

# The goals (SPEC section 9; eval/src/kinematics.rs and train/src/choose/step_ladder/ hold them).
STILL_MARGIN, LOW, HIGH, SPEED_DISTANCE, ACCELERATION_DISTANCE = 0.05, 0.8, 1.25, 0.2, 0.5
COVERAGE, JITTER = 95.0, 1.5
# Global diversity at least DIVERSITY where the clip's own intra diversity is at least VARIED.
DIVERSITY, VARIED = 1.2, 0.7


def misses(still, clip_still, ratios, speed_d, accel_d, coverage, replay, replay_goal, jitter,
           diversity=None, clip_intra=0.0):
    out = []
    if still > clip_still + STILL_MARGIN:
        out.append("still")
    for name, r in zip(("p25", "p50", "p90"), ratios):
        if not LOW <= r <= HIGH:
            out.append(name)
    if speed_d > SPEED_DISTANCE:
        out.append("speed d.")
    if accel_d > ACCELERATION_DISTANCE:
        out.append("accel. d.")
    if coverage < COVERAGE:
        out.append("coverage")
    if diversity is not None and clip_intra >= VARIED and diversity < DIVERSITY:
        out.append("diversity")
    if replay > replay_goal:
        out.append("replay")
    if jitter > JITTER:
        out.append("jitter")
    return ", ".join(out) or "none"


def row(name, still, clip_still, ratios, speed_d, accel_d, coverage, diversity, replay, floor,
        jitter, clip_intra=0.0):
    goal = max(1.0, floor)
    missed = misses(still, clip_still, ratios, speed_d, accel_d, coverage, replay, goal, jitter,
                    diversity, clip_intra)
    return (f"| {name} | {100 * still:.1f} ({100 * clip_still:.1f}) | "
            f"{' / '.join(f'{r:.2f}' for r in ratios)} | {speed_d:.2f} / {accel_d:.2f} | "
            f"{coverage:.1f} | {diversity:.3f} | {replay:.2f} ({floor:.2f}) | {jitter:.2f} | "
            f"{missed} |")


def eval_row(path, planted=False):
    d = json.loads(path.read_text())
    kind = "planted" if planted else "raw"
    k, c = d["kinematics"][kind], d["kinematics"]["clip"]
    report = d["planted_report"] if planted else d["report"]
    r = d["replay"]
    return row(path.stem, k["still_share"], c["still_share"], k["speed_ratios"],
               k["speed_distance"], k["acceleration_distance"], report["coverage"]["mean"],
               report["global_diversity"]["mean"], r["mean_seconds"],
               r.get("clip_backwards_seconds", 0.0), d["feet"][kind]["jitter_ratio"],
               d["report"]["clip_intra_diversity"])


def rung_row(run, path):
    d = json.loads(path.read_text())
    k = d["kinematics"]
    return row(f"{run} rung {d['steps']}", k["still_share"], d["clip_still_share"],
               k["speed_ratios"], k["speed_distance"], k["acceleration_distance"], d["coverage"],
               d["global_diversity"], d["replay_seconds"], d["replay_floor_seconds"],
               d["jitter_ratio"])


def main(out, rungs, planted):
    print("| run | still % (clip) | speed p25 / p50 / p90 x clip | speed / accel. distance "
          "| coverage | global div. | replay s (backwards) | jitter x clip | misses |")
    print("|---|---|---|---|---|---|---|---|---|")
    for path in sorted(out.glob("*.json")):
        print(eval_row(path, planted))
    if rungs:
        for ladder in sorted(out.glob("*/step_ladder")):
            checks = sorted(ladder.glob("steps-*/check.json"),
                            key=lambda p: int(p.parent.name.split("-")[1]))
            for check in checks:
                print(rung_row(ladder.parent.name, check))


if __name__ == "__main__":
    if len(sys.argv) < 2:
        sys.exit(__doc__)
    main(pathlib.Path(sys.argv[1]), "--rungs" in sys.argv[2:], "--planted" in sys.argv[2:])
