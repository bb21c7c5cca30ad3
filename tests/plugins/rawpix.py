#!/usr/bin/env python3
"""A persistent plug-in that answers with raw pixels (docs/plugins.md, "Raw
pixels"), for tests/raw_pixels.rs. It speaks through workers/jsonlines.py,
the module scenefit's own workers use. Every pixel is (R, G, B) =
(10, 20, 30); what it writes depends on the first light's intensity k
(1.000, 1.001, ...: the last digit):

  0  raw pixels, exactly width*height*3 bytes
  1  raw pixels, 5 bytes short
  2  raw pixels, 7 bytes too many
  3  a PNG file, answered without "pixels" (an older worker)
"""

import os
import sys

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, os.path.join(HERE, "..", "..", "workers"))
sys.path.insert(0, os.path.join(HERE, "..", "..", "examples", "plugins"))

import jsonlines  # noqa: E402
import lambert  # noqa: E402


def render(scene, output, seed, raw):
    w, h = scene["image"]["width"], scene["image"]["height"]
    mode = int(round(scene["lights"][0]["intensity"] * 1000)) % 10
    pixels = bytes([10, 20, 30]) * (w * h)
    if mode == 3 or not raw:
        lambert.write_png(output, w, h, [[10, 20, 30] * w for _ in range(h)])
        return None
    if mode == 1:
        pixels = pixels[:-5]
    elif mode == 2:
        pixels += bytes(7)
    return jsonlines.write_raw(output, pixels)


def main():
    channel = jsonlines.Channel()
    channel.ready("rawpix 1")
    channel.serve(render)


if __name__ == "__main__":
    main()
