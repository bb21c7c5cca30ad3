"""scenefit's JSON-lines renderer protocol, the worker's side (docs/plugins.md).

One copy of the protocol for every persistent worker (workers/mitsuba_worker.py,
blender_scripts/worker.py); a worker supplies only its render function:

    import jsonlines
    channel = jsonlines.Channel()          # before anything prints to stdout
    ... set the renderer up ...
    channel.ready("myrenderer 1.0")
    channel.serve(render)                  # render(scene, output, seed, raw)

The protocol: stdout carries protocol lines only. The first is
``{"ready": true, "renderer": "..."}`` (or ``{"ready": false, "error": "..."}``
when set-up fails); then every request line
``{"id": 17, "scene": {...}, "output": "/path/17.png", "seed": 5}`` (seed
optional, default 0; other keys ignored) gets exactly one answer
``{"id": 17, "ok": true}`` or ``{"id": 17, "ok": false, "error": "..."}``. A
malformed line is answered ok:false (id null when none could be read) and the
worker keeps serving. EOF on stdin ends ``serve``.

Raw pixels (the protocol's optional extension): a request with
``"pixels": "raw"`` lets the worker write, instead of an image file, the
image's 8-bit sRGB RGB bytes (rows top to bottom, no header: exactly
width*height*3 bytes) at ``output``, and answer ``{"id": 17, "ok": true,
"pixels": "raw"}``; no image is encoded here nor decoded by scenefit. A
render function returns "raw" when it did so (``write_raw``), anything else
when it wrote an image file.

Whatever the renderer or Python print goes to stderr: ``Channel()`` keeps a
private duplicate of fd 1 for the protocol and points fd 1 at fd 2 (or at
/dev/null with ``quiet=True``).
"""

import json
import os
import sys
import traceback


class RequestError(Exception):
    """A request the worker cannot serve (a bad scene or request): answered
    ok:false with this message, without a traceback on stderr."""


class Channel:
    """The protocol's stdout, kept apart from everything else printed."""

    def __init__(self, quiet=False):
        sys.stdout.flush()
        self._out = os.fdopen(os.dup(1), "w", buffering=1, encoding="utf-8")
        if quiet:
            devnull = os.open(os.devnull, os.O_WRONLY)
            os.dup2(devnull, 1)
            os.close(devnull)
        else:
            os.dup2(2, 1)
        # Python-level prints follow fd 1's new target too.
        sys.stdout = sys.stderr

    def send(self, message):
        """Writes one protocol line."""
        self._out.write(json.dumps(message) + "\n")
        self._out.flush()

    def ready(self, renderer):
        """The ready line: the worker serves from now on."""
        self.send({"ready": True, "renderer": renderer})

    def failed(self, error):
        """The set-up failed: the client reports this message."""
        self.send({"ready": False, "error": error})

    def serve(self, render, on_error=None):
        """Answers requests until EOF. ``render(scene, output, seed, raw)``
        draws one scene into the file ``output``, as raw pixels when ``raw``
        is true and it can (then it returns "raw"); it raises RequestError for a bad
        scene, anything else for a failure (then ``on_error()`` runs, e.g. to
        drop a half-updated scene, and the traceback goes to stderr)."""
        stdin = sys.stdin.buffer
        while True:
            raw = stdin.readline()
            if not raw:
                break
            line = raw.decode("utf-8", errors="replace").strip()
            if not line:
                continue
            rid = None
            try:
                req = parse(line)
                rid = req.get("id")
                scene, output, seed, raw = fields(req)
                answer = {"id": rid, "ok": True}
                if render(scene, output, seed, raw) == "raw":
                    answer["pixels"] = "raw"
                self.send(answer)
            except RequestError as e:
                self.send({"id": rid, "ok": False, "error": str(e)})
            except Exception as e:
                traceback.print_exc(file=sys.stderr)
                if on_error is not None:
                    on_error()
                msg = str(e).strip() or type(e).__name__
                self.send({"id": rid, "ok": False, "error": "%s: %s" % (type(e).__name__, msg)})
        sys.stderr.flush()

    def close(self):
        self._out.close()


def parse(line):
    """A request line as a dict."""
    try:
        req = json.loads(line)
    except ValueError as e:
        raise RequestError("malformed request line: %s" % e)
    if not isinstance(req, dict):
        raise RequestError("malformed request: expected a JSON object")
    return req


def fields(req):
    """The request's scene, output path, seed (a non-negative integer) and
    whether raw pixels are welcome."""
    if "scene" not in req:
        raise RequestError("request: missing \"scene\"")
    output = req.get("output")
    if not isinstance(output, str) or not output:
        raise RequestError("request: missing \"output\" path")
    seed = req.get("seed", 0)
    if seed is None:
        seed = 0
    if not isinstance(seed, int) or isinstance(seed, bool) or seed < 0:
        raise RequestError("request: \"seed\" must be a non-negative integer, got %r" % (seed,))
    return req["scene"], output, seed, req.get("pixels") == "raw"


def write_raw(output, data):
    """Writes raw pixel bytes to ``output`` through a temporary name beside
    it (a half-written file is never read); returns "raw" for ``serve``."""
    out = os.path.abspath(output)
    tmp = os.path.join(os.path.dirname(out), ".%s.tmp%d" % (os.path.basename(out), os.getpid()))
    try:
        with open(tmp, "wb") as f:
            f.write(data)
        os.replace(tmp, out)
    except OSError as e:
        try:
            os.unlink(tmp)
        except OSError:
            pass
        raise RequestError("cannot write %s: %s" % (output, e))
    return "raw"
