"""Command line of the Python reference, mirroring `sinmdm`:

    python -m sinmdm_reference generate  --model M.onnx --frames N [--count C] [--seed S] [--steps S|all] -o OUT.json
    python -m sinmdm_reference inbetween --model M.onnx --reference REF.json --keep 0:60 --keep 180: -o OUT.json
    python -m sinmdm_reference expand    --model M.onnx --reference REF.json --prefix 2s --suffix 60 -o OUT.json
    python -m sinmdm_reference compose   --model M.onnx --reference REF.json --part LeftUpLeg --root -o OUT.json
    python -m sinmdm_reference harmonize --model M.onnx --content REF.json [--factor 2] [--free-share 0.02] -o OUT.json
    python -m sinmdm_reference stream    --model M.onnx --frames N [--block B] [--seed S] -o OUT.json

References are features files (`sinmdm encode CLIP.bvh -m M.onnx -o REF.json`); the output is
the unnormalised features of every sample, the same file `sinmdm ... --features-json` writes.
"""

import argparse
import sys

import numpy as np

from . import tasks
from .features import read_features, write_features
from .model import Model, ModelError
from .sampler import sample
from . import steer
from .stream import stream_features


def _steps(text):
    return None if text.lower() == "all" else int(text)


def main(argv=None):
    parser = argparse.ArgumentParser(prog="sinmdm_reference", description=__doc__,
                                     formatter_class=argparse.RawDescriptionHelpFormatter)
    sub = parser.add_subparsers(dest="command", required=True)

    def common(p):
        p.add_argument("-m", "--model", required=True)
        p.add_argument("-o", "--output", required=True, help="features JSON to write")
        p.add_argument("--count", type=int, default=1)
        p.add_argument("--seed", type=int, default=0)
        p.add_argument("--steps", default=None,
                       help="respaced steps S, or 'all' (default 50; a stream's 20 per block)")
        p.add_argument("--sampler", choices=["ancestral", "ddim", "dpm2m"], default="ancestral")
        p.add_argument("--eta", type=float, default=0.0)
        return p

    g = common(sub.add_parser("generate"))
    g.add_argument("--frames", type=int)
    g.add_argument("--seconds", type=float)
    ib = common(sub.add_parser("inbetween"))
    ib.add_argument("--reference", required=True)
    ib.add_argument("--keep", action="append", required=True)
    ib.add_argument("--ramp", type=int, default=tasks.INBETWEEN_RAMP)
    ex = common(sub.add_parser("expand"))
    ex.add_argument("--reference", required=True)
    ex.add_argument("--prefix", default="0")
    ex.add_argument("--suffix", default="0")
    ex.add_argument("--ramp", type=int, default=tasks.EXPAND_RAMP)
    co = common(sub.add_parser("compose"))
    co.add_argument("--reference", required=True)
    co.add_argument("--joints", default="")
    co.add_argument("--part", action="append", default=[])
    co.add_argument("--root", action="store_true")
    co.add_argument("--frames", action="append", default=[])
    co.add_argument("--ramp", type=int, default=tasks.INBETWEEN_RAMP)
    ha = common(sub.add_parser("harmonize"))
    ha.add_argument("--content", required=True)
    ha.add_argument("--factor", type=int, default=tasks.HARMONIZE_FACTOR)
    ha.add_argument("--free-share", type=float, default=tasks.HARMONIZE_FREE_SHARE)
    da = common(sub.add_parser("dance"))
    da.add_argument("--reference", required=True)
    da.add_argument("--reference-beats", required=True, help="frames of the reference, comma-separated")
    da.add_argument("--target-beats", required=True, help="frames of the output, comma-separated")
    da.add_argument("--frames", type=int, required=True)
    da.add_argument("--hold", type=int, default=tasks.DANCE_HOLD)
    da.add_argument("--ramp", type=int, default=tasks.DANCE_RAMP)
    da.add_argument("--order", choices=["shuffled", "reference"], default="shuffled")
    da.add_argument("--level", choices=["auto", "every", "every-other", "half"], default="auto")
    da.add_argument("--root", choices=["kept", "free"], default="kept")
    st = common(sub.add_parser("stream"))
    st.add_argument("--frames", type=int, required=True)
    st.add_argument("--block", type=int, default=None)
    st.add_argument("--velocity", default=None, help="a schedule of seconds,speed,turn (degrees/s) lines")
    st.add_argument("--path", default=None, help="one x,y,z ground position per frame (file frame), "
                    "or x,y,z,fx,fy,fz with the direction to face")
    st.add_argument("--face", default=None, help="x,y,z: the direction to face (file frame)")
    args = parser.parse_args(argv)

    method = (args.sampler, args.eta) if args.sampler == "ddim" else (args.sampler,)
    try:
        model = Model(args.model)
        fps = model.layout["fps"]
        inpainting = harmonization = None

        def reference(path):
            feats, _ = read_features(path)
            return feats[0]

        if args.steps is None:
            args.steps = "20" if args.command == "stream" else "50"
        if args.command == "stream":
            schedule = tasks.schedule_for(model, _steps(args.steps))
            commands = None
            if args.velocity:
                commands = steer.read_velocities(args.velocity, fps, args.frames)
            elif args.path:
                commands = steer.read_path(args.path)
            if args.face:
                if args.velocity:
                    raise ValueError("--face cannot go with --velocity (a velocity's turn sets the facing)")
                fields = [x for x in args.face.replace(";", ",").replace(" ", ",").split(",") if x.strip()]
                facing = tuple(float(x) for x in fields)
                if len(facing) != 3:
                    raise ValueError(f"--face takes three numbers x,y,z, got '{args.face}'")
                commands = steer.with_facing(commands, facing, args.frames)
            feats = stream_features(model, schedule, args.seed, args.frames, block=args.block, method=method,
                                    commands=commands)
            write_features(args.output, model.layout, feats[None])
            print(f"wrote {args.output}", file=sys.stderr)
            return 0
        if args.command == "generate":
            if args.frames is not None:
                frames = args.frames
            elif args.seconds is not None:
                frames = int(np.floor(args.seconds * fps + 0.5))
            else:
                frames = 2 * model.metadata["training"]["clip_frames"]
        elif args.command == "inbetween":
            ref = reference(args.reference)
            keep = [tasks.parse_span(s, fps, ref.shape[1]) for s in args.keep]
            frames, inpainting = tasks.plan_inbetween(model, ref, keep, args.ramp)
        elif args.command == "expand":
            ref = reference(args.reference)
            frames, inpainting = tasks.plan_expand(
                model, ref, tasks.parse_position(args.prefix, fps), tasks.parse_position(args.suffix, fps), args.ramp)
        elif args.command == "compose":
            ref = reference(args.reference)
            layout = model.layout
            names = [n for n in args.joints.split(",") if n]
            joints = tasks.joints_by_name(layout, names)
            for top in tasks.joints_by_name(layout, args.part):
                joints += tasks.subtree(layout, top)
            spans = [tasks.parse_span(s, fps, ref.shape[1]) for s in args.frames]
            frames, inpainting = tasks.plan_compose(model, ref, joints, args.root, spans, args.ramp)
        elif args.command == "dance":
            ref = reference(args.reference)
            frames_list = lambda text: [int(v) for v in text.split(",") if v.strip()]
            frames, inpainting = tasks.plan_dance(
                model, ref, frames_list(args.reference_beats), frames_list(args.target_beats),
                args.frames, args.hold, args.ramp, args.order, args.level, args.root == "kept",
                args.seed)
        else:
            ref = reference(args.content)
            frames, harmonization = tasks.plan_harmonize(model, ref, args.factor, args.free_share)
        if not 1 <= args.count <= tasks.MAX_SAMPLES:
            raise tasks.TaskError(f"--count must be between 1 and {tasks.MAX_SAMPLES}")
        if not 1 <= frames <= tasks.MAX_SAMPLE_FRAMES:
            raise tasks.TaskError(f"a sample of {frames} frames is not possible")
        schedule = tasks.schedule_for(model, _steps(args.steps))
        x = sample(model, schedule, args.count, frames, args.seed, inpainting, harmonization, method=method)
        write_features(args.output, model.layout, model.denormalize(x))
    except (ModelError, tasks.TaskError, ValueError, OSError) as e:
        print(f"error: {e}", file=sys.stderr)
        return 1
    print(f"wrote {args.output}", file=sys.stderr)
    return 0


if __name__ == "__main__":
    sys.exit(main())
