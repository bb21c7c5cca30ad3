#!/usr/bin/env python3
"""A renderer plug-in that fails on purpose, for scenefit's fault tests.
Renders that do not fail are made by examples/plugins/lambert.py.

One-shot:   faulty.py --fault MODE SCENE OUT
Persistent: faulty.py --worker --fault MODE [--after N]

MODE (env FAULTY_MODE overrides it when set; a worker started with env
FAULTY_PIDDIR set leaves an empty file named after its pid there):
  ok         render normally
  crash      one-shot: exit 3; worker: exit 3 while serving the request
  hang       sleep for an hour
  noimage    succeed (exit 0 / ok: true) without writing the image
  garbage    write a file that is not an image
  wrongsize  write an image of the wrong size (8x6)
  fifo       leave a FIFO (with no writer) where the image should be
  devzero    leave a link to /dev/zero where the image should be
  refuse     worker: answer ok: false
  noise      worker: print non-protocol lines (and a JSON line with another
             id that is not an answer) around every answer, then render
  longline   worker: print an endless line without a newline
  badjson    worker: answer with a truncated JSON line that has the id
  wrongid    worker: answer ok to another id
  hangafter  worker: hang once it has served --after requests
  limit      worker: answer ok: false once it has served --after requests
  dieafter   worker: exit after serving --after requests
  nostart    worker: exit before the ready line
  mixed      pick one of the faults above (or ok) from the first light's
             intensity, so that some candidates of a fit fail and others not
"""

import importlib.util
import json
import os
import sys
import time

HERE = os.path.dirname(os.path.abspath(__file__))
LAMBERT = os.path.join(HERE, "..", "..", "examples", "plugins", "lambert.py")

ONE_SHOT_MIX = ["ok", "crash", "ok", "noimage", "garbage", "ok", "wrongsize", "hang"]
WORKER_MIX = ["ok", "crash", "ok", "noimage", "garbage", "refuse", "wrongsize", "noise", "hang", "ok"]


def lambert():
    spec = importlib.util.spec_from_file_location("lambert", LAMBERT)
    mod = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(mod)
    return mod


def pick(mode, scene, mix):
    if mode != "mixed":
        return mode
    k = int(round(scene["lights"][0]["intensity"] * 1000))
    return mix[k % len(mix)]


def fault(mode, scene, out, renderer):
    """Does what MODE says for one render; returns the worker's ok flag."""
    if mode == "crash":
        sys.stderr.write("faulty.py: crashing on purpose\n")
        sys.stderr.flush()
        sys.exit(3)
    if mode == "hang":
        sys.stderr.write("faulty.py: hanging on purpose\n")
        sys.stderr.flush()
        time.sleep(3600)
    if mode == "noimage":
        return True
    if mode == "garbage":
        with open(out, "wb") as f:
            f.write(b"this is not a PNG file\n")
        return True
    if mode == "fifo":
        os.mkfifo(out)
        return True
    if mode == "devzero":
        os.symlink("/dev/zero", out)
        return True
    if mode == "wrongsize":
        renderer.write_png(out, 8, 6, [[128] * 24 for _ in range(6)])
        return True
    renderer.render(scene, out)
    return True


def one_shot(mode, scene_path, out):
    with open(scene_path) as f:
        scene = json.load(f)
    fault(pick(mode, scene, ONE_SHOT_MIX), scene, out, lambert())
    return 0


def worker(mode, after):
    renderer = lambert()
    piddir = os.environ.get("FAULTY_PIDDIR")
    if piddir:
        open(os.path.join(piddir, str(os.getpid())), "w").close()
    if mode == "nostart":
        sys.stderr.write("faulty.py: refusing to start\n")
        return 4
    print("faulty.py: a line that is not JSON, before the ready line", flush=True)
    print(json.dumps({"ready": True, "renderer": "faulty.py"}), flush=True)
    served = 0
    for line in sys.stdin:
        if not line.strip():
            continue
        req = json.loads(line)
        rid = req["id"]
        m = pick(mode, req["scene"], WORKER_MIX)
        if m == "dieafter" and served >= after:
            sys.stderr.write("faulty.py: exiting after %d requests\n" % served)
            return 5
        if m == "limit" and served >= after:
            served += 1
            print(json.dumps({"id": rid, "ok": False, "error": "served too many requests"}), flush=True)
            continue
        if m == "refuse":
            sys.stderr.write("faulty.py: refusing on purpose\n")
            print(json.dumps({"id": rid, "ok": False, "error": "refused on purpose"}), flush=True)
            continue
        if m == "longline":
            chunk = "x" * 65536
            while True:
                sys.stdout.write(chunk)
                sys.stdout.flush()
        if m == "badjson":
            print('{"id": %d, "ok": tru' % rid, flush=True)
            continue
        if m == "wrongid":
            print(json.dumps({"id": rid + 1000, "ok": True}), flush=True)
            continue
        if m == "hangafter" and served >= after:
            fault("hang", req["scene"], req["output"], renderer)
        if m == "noise":
            print("some log line on stdout", flush=True)
            print(json.dumps({"id": -1, "note": "not an answer"}), flush=True)
            print("[1, 2, 3]", flush=True)
            m = "ok"
        fault(m if m not in ("dieafter", "limit", "hangafter") else "ok", req["scene"], req["output"], renderer)
        served += 1
        print(json.dumps({"id": rid, "ok": True}), flush=True)
    return 0


def main(argv):
    mode, after, is_worker, rest = "ok", 0, False, []
    i = 0
    while i < len(argv):
        a = argv[i]
        if a == "--fault":
            mode = argv[i + 1]
            i += 1
        elif a == "--after":
            after = int(argv[i + 1])
            i += 1
        elif a == "--worker":
            is_worker = True
        else:
            rest.append(a)
        i += 1
    mode = os.environ.get("FAULTY_MODE") or mode
    if is_worker:
        return worker(mode, after)
    return one_shot(mode, rest[0], rest[1])


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
