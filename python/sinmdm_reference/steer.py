"""Steering (runtime/src/steer): the root's slow motion pulled to per-frame commands at every
denoising step, for models with a heading-relative root. Every operation follows the Rust code's
order, with the platform's libm for sin, cos and atan2 (Python's `math`, as Rust's f64 methods),
so the same machine gives the same bits."""

import math

import numpy as np

from .tasks import soft_mask

STEER_REACH_SECONDS = 0.5
STEER_PASSES = 4
FACING_REACH_SECONDS = 1.5
FACING_CATCH_UP_SECONDS = 1.0
MIN_TURN_LIMIT = math.pi / 2
UP = 1
FORWARD, LEFTWARD, TURN = 0, 1, 2

# file_from_canonical of each up axis (runtime/src/motion/up.rs); entries 0 and +-1.
FILE_FROM_CANONICAL = {
    "+Y": ((1.0, 0.0, 0.0), (0.0, 1.0, 0.0), (0.0, 0.0, 1.0)),
    "-Y": ((1.0, 0.0, 0.0), (0.0, -1.0, 0.0), (0.0, 0.0, -1.0)),
    "+Z": ((1.0, 0.0, 0.0), (0.0, 0.0, -1.0), (0.0, 1.0, 0.0)),
    "-Z": ((1.0, 0.0, 0.0), (0.0, 0.0, 1.0), (0.0, -1.0, 0.0)),
    "+X": ((0.0, 1.0, 0.0), (-1.0, 0.0, 0.0), (0.0, 0.0, 1.0)),
    "-X": ((0.0, -1.0, 0.0), (1.0, 0.0, 0.0), (0.0, 0.0, 1.0)),
}


def mat_vec(m, v):
    """Row by row, each a left-to-right dot product (Rust's Mat3 * Vec3)."""
    return [m[r][0] * v[0] + m[r][1] * v[1] + m[r][2] * v[2] for r in range(3)]


def yaw(h):
    """The rotation by h about up (axis_rotation(1, h))."""
    s, c = math.sin(h), math.cos(h)
    return ((c, 0.0, s), (0.0, 1.0, 0.0), (-s, 0.0, c))


def transpose(m):
    return tuple(tuple(m[c][r] for c in range(3)) for r in range(3))


def round_half_away(x):
    """Rust's f64::round: to the nearest integer, halves away from zero (exactly)."""
    t = float(math.trunc(x))
    if abs(x - t) >= 0.5:
        t += math.copysign(1.0, x)
    return t


def wrap(angle):
    tau = math.tau
    a = angle - tau * round_half_away(angle / tau)
    return a + tau if a <= -math.pi else a


def norm(v):
    return math.sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2])


def triangular(values, reach):
    """The triangular low-pass of half-width `reach` (weights reach + 1 - |k|), renormalised
    at the ends; sums in the order of the Rust loop (k from -reach up)."""
    values = np.asarray(values, dtype=np.float64)
    n = len(values)
    if reach == 0 or n == 0:
        return values.copy()
    total = np.zeros(n)
    weight = np.zeros(n)
    index = np.arange(n)
    for k in range(-reach, reach + 1):
        j = index + k
        inside = (j >= 0) & (j < n)
        w = float(reach + 1 - abs(k))
        total = np.where(inside, total + w * values[np.clip(j, 0, n - 1)], total)
        weight = np.where(inside, weight + w, weight)
    return total / weight


def limits(model):
    """(forward lo, forward hi, turn) of SteerLimits::of."""
    fps = model.layout["fps"]
    fm, fs = float(model.mean[FORWARD]) * fps, float(model.std[FORWARD]) * fps
    tm, ts = float(model.mean[TURN]) * fps, float(model.std[TURN]) * fps
    return fm - 2.0 * fs, fm + 2.0 * fs, max(abs(tm) + 2.0 * ts, MIN_TURN_LIMIT)


def sideways_limits(model):
    """(leftward lo, leftward hi) of SteerLimits::of, units per second."""
    fps = model.layout["fps"]
    lm, ls = float(model.mean[LEFTWARD]) * fps, float(model.std[LEFTWARD]) * fps
    return lm - 2.0 * ls, lm + 2.0 * ls


def to_canonical(model):
    return transpose(FILE_FROM_CANONICAL[model.layout.get("up", "+Y").upper()])


def facing_of_direction(model, direction):
    """facing_of_direction: the canonical heading facing a file-frame ground direction, or None."""
    largest = 0.0
    for v in direction:
        largest = max(largest, abs(v))
    if not (math.isfinite(largest) and largest > 0.0):
        return None
    scale = 1.0 / largest
    d = mat_vec(to_canonical(model), [v * scale for v in direction])
    d[UP] = 0.0
    if not norm(d) > 1e-9:
        return None
    return math.atan2(d[0], d[2])


def goal_position(goal):
    return goal[1] if goal is not None and goal[0] == "course" else None


def integrate(features, start_position, start_heading):
    """A heading root's canonical positions and facings from raw features [F, N] (integrate)."""
    n = features.shape[1]
    rows = [[float(v) for v in features[r]] for r in range(4)]
    positions, headings = [], []
    p, h = list(start_position), start_heading
    for f in range(n):
        if f > 0:
            h += rows[2][f]
            step = mat_vec(yaw(h), (rows[1][f], 0.0, rows[0][f]))
            p = [p[i] + step[i] for i in range(3)]
        p[UP] = rows[3][f]
        positions.append(list(p))
        headings.append(h)
    return positions, headings


class Steering:
    """plan_steering's guidance: goals per window frame from a known course at `anchor`."""

    def __init__(self, model, goals, weights, anchor, course):
        fps = model.layout["fps"]
        self.goals = goals
        self.weights = [float(w) for w in weights]
        self.anchor = anchor
        position, heading = course
        self.course = ([position[0], 0.0, position[2]], heading)
        self.mean = [float(model.mean[r]) for r in (FORWARD, LEFTWARD, TURN)]
        self.std = [float(model.std[r]) for r in (FORWARD, LEFTWARD, TURN)]
        self.reach = int(round_half_away(STEER_REACH_SECONDS * fps))
        # A path's facing is pulled over a longer reach (Rust: plan_steering's turn_reach).
        on_path = any(g is not None and g[0] == "course" and g[1] is not None and g[2] is None
                      for g in goals[anchor + 1:])
        self.turn_reach = int(round_half_away(FACING_REACH_SECONDS * fps)) if on_path else self.reach
        self.catch_up = max(FACING_CATCH_UP_SECONDS * fps, 1.0)
        lo, hi, _ = limits(model)
        self.max_step = max(hi, 0.0) / fps
        self.backward_floor = min(lo, 0.0) / fps
        side_lo, side_hi = sideways_limits(model)
        self.sideways_range = (min(side_lo, 0.0) / fps, max(side_hi, 0.0) / fps)

    def apply(self, x0):
        """x0 [F, N] float32, normalised; changed in place."""
        for _ in range(STEER_PASSES):
            self._pass(x0)

    def _pass(self, x0):
        n = len(self.goals)
        raw = [[float(v) * self.std[k] + self.mean[k] for v in x0[k]] for k in range(3)]
        forward, leftward, turn = raw
        heading = [self.course[1]] * n
        position = [list(self.course[0]) for _ in range(n)]
        for i in range(self.anchor + 1, n):
            heading[i] = heading[i - 1] + turn[i]
            step = mat_vec(yaw(heading[i]), (leftward[i], 0.0, forward[i]))
            step[UP] = 0.0
            position[i] = [position[i - 1][c] + step[c] for c in range(3)]
        targets = [[None] * n for _ in range(3)]
        span = None
        last_direction = 0.0
        for i in range(self.anchor + 1, n):
            goal = self.goals[i]
            if goal is None:
                span = None
            elif goal[0] == "velocity":
                targets[FORWARD][i] = goal[1]
                targets[TURN][i] = goal[2]
                span = None
            else:
                _, goal_pos, facing = goal
                parts = (goal_pos is not None, facing is not None)
                p = goal_pos if goal_pos is not None else position[i - 1]
                before = goal_position(self.goals[i - 1])
                if before is None:
                    before = p
                path_step = [p[c] - before[c] for c in range(3)]
                path_step[UP] = 0.0
                if span is not None and span[3] != parts:
                    span = None
                if span is None:
                    if facing is not None:
                        direction = facing
                    else:
                        lead = path_step
                        following = goal_position(self.goals[i + 1]) if i + 1 < n else None
                        if norm(lead) <= 1e-12 and following is not None:
                            lead = [following[c] - p[c] for c in range(3)]
                            lead[UP] = 0.0
                        if norm(lead) > 1e-12:
                            direction = math.atan2(lead[0], lead[2])
                        else:
                            direction = heading[i - 1]
                    last_direction = heading[i - 1] + wrap(direction - heading[i - 1])
                    offset = [before[c] - position[i - 1][c] for c in range(3)]
                    offset[UP] = 0.0
                    span = (i, offset, heading[i - 1] - last_direction, parts)
                start, offset, facing_offset, _ = span

                def fade(frame):
                    return max(1.0 - (frame + 1 - start) / self.catch_up, 0.0)

                now = fade(i)
                then = fade(i - 1) if i > start else 1.0
                if goal_pos is not None:
                    shift = then - now
                    want = [path_step[c] + offset[c] * shift for c in range(3)]
                    speed = norm(want)
                    if speed > self.max_step and speed > 0.0:
                        scale = self.max_step / speed
                        want = [w * scale for w in want]
                    local = mat_vec(transpose(yaw(heading[i])), want)
                    ahead, aside = local[2], local[0]
                    if facing is not None:
                        ahead = max(ahead, self.backward_floor)
                        aside = min(max(aside, self.sideways_range[0]), self.sideways_range[1])
                    targets[FORWARD][i] = ahead
                    targets[LEFTWARD][i] = aside
                if facing is not None:
                    direction = last_direction + wrap(facing - last_direction)
                elif norm(path_step) > 1e-12:
                    direction = last_direction + wrap(math.atan2(path_step[0], path_step[2]) - last_direction)
                else:
                    direction = last_direction
                targets[TURN][i] = (direction + facing_offset * now) - (last_direction + facing_offset * then)
                last_direction = direction
        for k in range(3):
            if all(t is None for t in targets[k]):
                continue
            current = raw[k]
            pull = [0.0 if targets[k][i] is None else self.weights[i] * (targets[k][i] - current[i])
                    for i in range(n)]
            slow = triangular(pull, self.turn_reach if k == TURN else self.reach)
            x0[k] = np.array([np.float32(float(v) + d / self.std[k]) for v, d in zip(x0[k], slow)],
                             dtype=np.float32)


def plan_steering(model, commands, anchor, course, ramp):
    """commands: per window frame None, ("velocity", forward, turn) in units/s and rad/s,
    ("position", (x, y, z)), ("facing", (x, y, z)) or ("position_facing", (x, y, z), (fx, fy, fz))
    in the file frame. None when nothing is asked."""
    fps = model.layout["fps"]
    lo, hi, turn_limit = limits(model)
    canonical = to_canonical(model)
    goals = []
    for i, c in enumerate(commands):
        if c is None:
            goals.append(None)
        elif c[0] == "velocity":
            f = min(max(c[1], lo), hi)
            t = min(max(c[2], -turn_limit), turn_limit)
            goals.append(("velocity", f / fps, t / fps))
        else:
            position = facing = None
            if c[0] in ("position", "position_facing"):
                position = mat_vec(canonical, c[1])
                position[UP] = 0.0
            if c[0] in ("facing", "position_facing"):
                facing = facing_of_direction(model, c[-1])
                if facing is None:
                    raise ValueError(f"command {i} asks to face {c[-1]}, which has no direction on the ground")
            goals.append(("course", position, facing))
    asked = np.array([i > anchor and g is not None for i, g in enumerate(goals)])
    if not asked.any():
        return None
    weights = soft_mask(asked, ramp)
    return Steering(model, goals, weights, anchor, course)


def start_course(model):
    root = model.layout["root"]
    return [float(v) for v in root["start_position"]], float(root["heading"]["start"])


def _triples(path):
    """Rows of three numbers (commas, semicolons, spaces or tabs between them); a first line
    that is not numbers is a header (as the command line reads them)."""
    rows = []
    with open(path) as f:
        for i, line in enumerate(f):
            fields = [x for x in line.replace(";", ",").replace("\t", ",").replace(" ", ",").split(",") if x.strip()]
            if not fields:
                continue
            try:
                rows.append([float(x) for x in fields])
            except ValueError:
                if i == 0:
                    continue
                raise
    return rows


def read_velocities(path, fps, frames):
    """`seconds,speed,turn` lines (turn in degrees per second) as per-frame commands."""
    entries = [(v[0], v[1], math.radians(v[2])) for v in _triples(path)]
    out = []
    for f in range(frames):
        t = f / fps
        found = [e for e in entries if e[0] <= t]
        out.append(("velocity", found[-1][1], found[-1][2]) if found else None)
    return out


def read_path(path):
    """x,y,z per line, or x,y,z,fx,fy,fz: a position and the direction to face there."""
    out = []
    for v in _triples(path):
        if len(v) == 3:
            out.append(("position", (v[0], v[1], v[2])))
        elif len(v) == 6:
            out.append(("position_facing", (v[0], v[1], v[2]), (v[3], v[4], v[5])))
        else:
            raise ValueError(f"{path}: a row of {len(v)} numbers; expected x,y,z or x,y,z,fx,fy,fz")
    return out


def with_facing(commands, facing, frames):
    """--face: the path's positions walked in `facing`, or, without a path, `frames` frames of it.
    A path that brings its own facings is refused, as the command line refuses it."""
    if commands is None:
        return [("facing", facing)] * frames
    if any(c is not None and c[0] != "position" for c in commands):
        raise ValueError("--face with a path that gives its own facings (six numbers a line): give one or the other")
    return [("position_facing", c[1], facing) for c in commands]
