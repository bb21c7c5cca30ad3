"""Median and largest light-direction error (degrees) of a set's fit or
diagnosis against true directions, one "x y z" line per photograph in
shot order (or, for names that are numbers, the line of that number,
counted from FIRST: 0 for scripts/mitsuba-set.py, 1 for DiLiGenT).

    python3 scripts/light-error.py RESULT_OR_DIAGNOSIS.json LIGHTS.txt [FIRST] [PARAM]

PARAM: the per-shot direction's free path (default lights.led.direction).
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
errors = []
for k, shot in enumerate(shots):
    name = shot["name"]
    t = truth[int(name) - first] if name.isdigit() else truth[k]
    d = shot["params"][param]
    cos = sum(a * b for a, b in zip(d, t)) / math.sqrt(sum(x * x for x in d)) / math.sqrt(sum(x * x for x in t))
    errors.append(math.degrees(math.acos(max(-1.0, min(1.0, cos)))))
errors.sort()
n = len(errors)
median = 0.5 * (errors[(n - 1) // 2] + errors[n // 2])
print(f"median {median:.2f} max {errors[-1]:.2f} over {n} (accepted: {run.get('accepted')})")
