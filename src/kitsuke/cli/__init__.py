"""The `kitsuke` command: `kitsuke <group> <verb> ...`.

Thin by design: each group module (`cli/<group>.py`) parses its arguments and calls the library. Errors follow SPEC §2:
bad input -> one line on stderr naming the file and the problem, exit code 2; a computation that gave no usable
result (diverged, not a garment on the body) -> one line naming the stage, exit code 1, nothing written as if it
worked; an internal error -> exit code 1 (set KITSUKE_DEBUG=1 for the traceback).
"""

from __future__ import annotations

import argparse
import atexit
import importlib
import os
import signal
import sys
import threading
import traceback

from ..errors import ComputationError, InputError

#: group name -> (module under kitsuke.cli, one-line help). Modules are imported only when their group runs or
#: when `--help` lists them, so `kitsuke --help` stays fast.
GROUPS: dict[str, tuple[str, str]] = {
    "demo": ("demo", "write the default body, kimono pattern and renders to out/"),
    "body": ("body", "inspect and convert body meshes"),
    "pattern": ("pattern", "convert, validate, mesh and generate sewing patterns"),
    "strokes": ("strokes", "propose a stroke set from a pattern's placement, or check a strokes file"),
    "dress": ("dress", "put a garment on a body from a pattern and stroke pairs (wrap + settle), or re-wrap it"),
    "drag": ("drag", "drag a dressed garment along the body, with pins (replays a drags file)"),
    "render": ("render", "render meshes to PNG"),
    "pose": ("pose", "extract poses from video/images/camera/BVH, correct them for a kimono, animate the body"),
    "kimono": ("kimono", "simulate the kimono on a body moved by poses; calibrate its posture limits E"),
    "app": ("app", "the browser app: draw strokes on the pattern and the body, wrap, save"),
    "tryon": ("tryon", "the kimono try-on mirror: video, images or camera in, the person wearing a kimono out"),
    "batch": ("batch", "run many dress jobs or kimono calibrations from a manifest, locally or on Ray"),
}

EPILOG = """\
examples:
  kitsuke demo                                   # default body + kimono into out/
  kitsuke body info body.obj                     # units, size, holes, rig
  kitsuke pattern kimono -o kimono.json          # standard-size kimono pattern
  kitsuke pattern convert shirt_spec.json shirt.svg
  kitsuke pattern mesh kimono.json -o kimono.obj
  kitsuke strokes suggest --body mean_all.obj --pattern shirt_spec.json -o strokes.json
  kitsuke dress --body mean_all.obj --pattern shirt_spec.json --strokes strokes.json -o shirt.glb
  kitsuke render body.glb -o front.png --view front
  kitsuke pose extract clip.mp4 -o poses.json    # MediaPipe, bundled model; also BVH, images, --camera 0
  kitsuke pose correct clip.mp4 -o fixed.json --plot legs.png --video overlay.mp4
  kitsuke pose animate walk.bvh -o walk.glb        # the default body, skinned and animated
  kitsuke kimono simulate --poses walk.bvh -o walk_kimono.glb --video walk_kimono.mp4   # the kimono moving
  kitsuke kimono calibrate -o limits.json --plot limits.png                          # E(θ) by simulation
  kitsuke app                                    # the browser app on http://127.0.0.1:8080
  kitsuke tryon clip.mp4 -o clip_kimono.mp4 --compare   # the try-on mirror on a video (--camera 0 --window: live)
  kitsuke batch dress jobs.csv -o out/            # one dress per manifest row, on every core (or --address)

Run `kitsuke <group> --help` for a group's verbs and options.

limits: inputs past a resource limit are refused before the work, naming the limit. Raise one with
  --limit NAME=VALUE anywhere on the command line (repeatable), or KITSUKE_LIMIT_<NAME>=VALUE. Defaults:
  {limits}
"""


class _Parser(argparse.ArgumentParser):
    """ArgumentParser whose usage errors are one line plus the hint to ask for --help (exit 2)."""

    def error(self, message: str) -> None:  # type: ignore[override]
        self.exit(2, f"{self.prog}: error: {message} (see {self.prog} --help)\n")


class _Terminated(BaseException):
    """SIGTERM, raised where the program is so that every atomic write in progress removes its temporary file."""


def _on_terminate():
    """Turn SIGTERM into `_Terminated` (from the main thread only); returns the previous handler, or None."""

    def handler(signum, frame):
        raise _Terminated

    try:
        return signal.signal(signal.SIGTERM, handler)
    except ValueError:  # not the main thread: leave signals alone
        return None


def _limit_defaults() -> str:
    import dataclasses

    from ..limits import Limits

    return ", ".join(f"{f.name}={getattr(Limits(), f.name):.10g}" for f in dataclasses.fields(Limits))


def _split_limits(argv: list[str]) -> tuple[list[str], list[str]]:
    """Take every `--limit NAME=VALUE` (or `--limit=NAME=VALUE`) out of argv, wherever it is."""
    rest, limits = [], []
    it = iter(argv)
    for a in it:
        if a == "--limit":
            limits.append(next(it, ""))
        elif a.startswith("--limit="):
            limits.append(a[len("--limit=") :])
        else:
            rest.append(a)
    return rest, limits


def build_parser(only: str | None = None) -> argparse.ArgumentParser:
    parser = _Parser(
        prog="kitsuke",
        description="kitsuke: put garments on 3D people (sketch-based dressing, kimono try-on mirror).",
        epilog=EPILOG.format(limits=_limit_defaults()),
        formatter_class=argparse.RawDescriptionHelpFormatter,
    )
    from .. import __version__

    parser.add_argument("--version", action="version", version=f"kitsuke {__version__}")
    sub = parser.add_subparsers(dest="group", metavar="<group>", parser_class=_Parser)
    for name, (module, help_text) in GROUPS.items():
        if only is not None and name != only:
            sub.add_parser(name, help=help_text)
            continue
        mod = importlib.import_module(f".{module}", __name__)
        mod.register(sub.add_parser(name, help=help_text, description=help_text))
    return parser


def main(argv: list[str] | None = None) -> int:
    argv = sys.argv[1:] if argv is None else argv
    argv, limit_args = _split_limits(argv)
    group = next((a for a in argv if not a.startswith("-")), None)
    parser = build_parser(only=group if group in GROUPS else None)
    args = parser.parse_args(argv)
    if getattr(args, "run", None) is None:
        # A group without a verb: show what it offers.
        target = parser if args.group is None else parser._subparsers._group_actions[0].choices[args.group]  # type: ignore[union-attr]
        target.print_help()
        return 2 if args.group is None else 0
    previous = _on_terminate()
    try:
        from .. import limits

        changes = dict(limits.parse_limit(a) for a in limit_args)
        with limits.raised(**changes):
            return int(args.run(args) or 0)
    except _Terminated:
        print("kitsuke: terminated", file=sys.stderr)
        return 143
    except InputError as e:
        print(f"kitsuke: error: {e}", file=sys.stderr)
        return 2
    except ComputationError as e:
        print(f"kitsuke: failed: {e}", file=sys.stderr)
        return 1
    except KeyboardInterrupt:
        print("kitsuke: interrupted", file=sys.stderr)
        return 130
    except BrokenPipeError:
        # Whoever read the output stopped reading (`kitsuke pattern info P | head`): end quietly, as Unix tools
        # do, with the status of a process that SIGPIPE ended; stdout goes nowhere, so no later flush fails.
        os.dup2(os.open(os.devnull, os.O_WRONLY), sys.stdout.fileno())
        return 141
    except Exception as e:  # noqa: BLE001 - the last line of defence: an internal error, not the user's fault
        if os.environ.get("KITSUKE_DEBUG"):
            traceback.print_exc()
        print(
            f"kitsuke: internal error: {type(e).__name__}: {e} (set KITSUKE_DEBUG=1 for details)",
            file=sys.stderr,
        )
        return 1
    finally:
        if previous is not None:
            signal.signal(signal.SIGTERM, previous)


def run() -> None:
    """The `kitsuke` program (`python -m kitsuke`): `main`, then the process ends at once.

    Why: tearing down the interpreter's modules (numba, scipy, ...) took 0.14 s of a 2.2 s warm `kitsuke dress`
    (measured, 2 cores). Every output is written and closed by then (atomic writes, context managers), and the
    exit handlers run first (Ray's shutdown, temporary folders); with another non-daemon thread still running the
    process ends the ordinary way, which waits for it.
    """
    code = main()
    if any(t.is_alive() and not t.daemon for t in threading.enumerate() if t is not threading.main_thread()):
        sys.exit(code)
    atexit._run_exitfuncs()
    for stream in (sys.stdout, sys.stderr):
        try:
            stream.flush()
        except (OSError, ValueError):  # a closed pipe or stream: nothing more can reach it
            pass
    os._exit(code)


if __name__ == "__main__":
    run()
