"""Median and largest light-direction error (degrees) of a set's fit or
diagnosis against true directions, one "x y z" line per photograph in
shot order (of the shots fitted: with shots held out, name them by
number) (or, for names that are numbers, the line of that number,
counted from FIRST: 0 for scripts/mitsuba-set.py, 1 for DiLiGenT).

    python3 scripts/light-error.py RESULT_OR_DIAGNOSIS.json LIGHTS.txt [FIRST] [PARAM]

PARAM: the per-shot direction's free path (default lights.led.direction).
Photographs held out (`held_out`, their lights as predicted) are not in
the first line; a second line gives each one's error (? for a held-out
shot whose name is not a number: its line is not known).
"""
import json
import math
import sys

path, lights = sys.argv[1], sys.argv[2]
first = int(sys.argv[3]) if len(sys.argv) > 3 else 0
param = sys.argv[4] if len(sys.argv) > 4 else "lights.led.direction"
truth = [list(map(float, line.split())) for line in open(lights) if line.strip()]
run = json.load(open(path))
shots = run.get("shots") or run.get("shots_after")


def error(shot, k):
    """Degrees between the shot's fitted direction and its true one; None
    when its line is unknown (k None: a held-out shot not named by number)."""
    name = shot["name"]
    if not name.isdigit() and k is None:
        return None
    t = truth[int(name) - first] if name.isdigit() else truth[k]
    d = shot["params"][param]
    cos = sum(a * b for a, b in zip(d, t)) / math.sqrt(sum(x * x for x in d)) / math.sqrt(sum(x * x for x in t))
    return math.degrees(math.acos(max(-1.0, min(1.0, cos))))


errors = sorted(error(shot, k) for k, shot in enumerate(shots))
n = len(errors)
median = 0.5 * (errors[(n - 1) // 2] + errors[n // 2])
print(f"median {median:.2f} max {errors[-1]:.2f} over {n} (accepted: {run.get('accepted')})")
held = run.get("held_out") or []
if held:
    # shots.json's order is not in the run's files: a held-out shot is
    # matched to its line by its number only
    each = ", ".join(f"{h['name']} " + ("?" if e is None else f"{e:.2f}")
                     for h, e in ((h, error(h, None)) for h in held))
    print(f"held out (predicted): {each}")
