#!/usr/bin/env python3
"""A latency-bound fake renderer worker, for scenefit's scale-out figures
(docs/scale-out.md): a persistent plug-in (docs/plugins.md) that sleeps a
fixed time per render and then writes a flat grey PNG of the scene's size,
so that what is measured is scenefit's and the executor's overhead, not
rendering.

    sleepy.py [--sleep SECONDS]               persistent (default 0.05 s)
    sleepy.py [--sleep SECONDS] SCENE OUT     one-shot: one render, then exit
"""

import json
import struct
import sys
import time
import zlib


def png(width, height):
    """A grey 8-bit RGB PNG of the given size."""
    raw = b"".join(b"\x00" + b"\x80" * (3 * width) for _ in range(height))

    def chunk(kind, data):
        body = kind + data
        return struct.pack(">I", len(data)) + body + struct.pack(">I", zlib.crc32(body) & 0xFFFFFFFF)

    header = struct.pack(">IIBBBBB", width, height, 8, 2, 0, 0, 0)
    return (b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", header)
            + chunk(b"IDAT", zlib.compress(raw)) + chunk(b"IEND", b""))


def main():
    pause = 0.05
    args = sys.argv[1:]
    if len(args) >= 2 and args[0] == "--sleep":
        pause = float(args[1])
        args = args[2:]
    if len(args) == 2:
        with open(args[0]) as f:
            image = json.load(f)["image"]
        time.sleep(pause)
        with open(args[1], "wb") as f:
            f.write(png(int(image["width"]), int(image["height"])))
        return
    if args:
        sys.exit("usage: sleepy.py [--sleep SECONDS] [SCENE OUT]")
    images = {}
    out = sys.stdout
    out.write(json.dumps({"ready": True, "renderer": "sleepy"}) + "\n")
    out.flush()
    for line in sys.stdin:
        line = line.strip()
        if not line:
            continue
        rid = None
        try:
            req = json.loads(line)
            rid = req["id"]
            size = (int(req["scene"]["image"]["width"]), int(req["scene"]["image"]["height"]))
            if size not in images:
                images[size] = png(*size)
            time.sleep(pause)
            with open(req["output"], "wb") as f:
                f.write(images[size])
            answer = {"id": rid, "ok": True}
        except Exception as e:  # a bad request fails that request only
            answer = {"id": rid, "ok": False, "error": str(e)}
        out.write(json.dumps(answer) + "\n")
        out.flush()


if __name__ == "__main__":
    main()
