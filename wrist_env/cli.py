"""`wrist-bench`: the command line of wrist-env (a thin shell over the package)."""

from __future__ import annotations

import argparse
import json
import sys
import time
from pathlib import Path

FIGURES = Path("experiments") / "figures"


def _participants(args) -> int:
    from wrist_env.participants import builtin, registry

    for folder in args.folder or []:
        registry.add_folder(folder)
    for name in registry.participants():
        if name in builtin.BUILTIN:
            i = builtin.info(name)
            print(f"{name}  built-in (synthetic)  {i.sex}, {i.age} y, facet type {i.facet_type}, task: {i.task}")
        else:
            print(f"{name}  folder {registry._FOLDERS[name]}")
    return 0


def _build(args) -> int:
    from wrist_env.participants import registry

    for folder in args.folder or []:
        registry.add_folder(folder)
    start = time.perf_counter()
    model = registry.load_model(args.participant, cache=not args.no_cache)
    summary = dict(model.report)
    summary["wall_seconds"] = round(time.perf_counter() - start, 2)
    if args.json:
        print(json.dumps(summary, indent=2))
    else:
        print(f"{model.name}: built in {summary['build_seconds']} s "
              f"(this call {summary['wall_seconds']} s); morph error (mm): "
              + ", ".join(f"{b} {e['mean']:.2f}/{e['max']:.2f}" for b, e in summary["morph_error_mm"].items()))
    return 0


def _figure(args) -> int:
    from wrist_env import figures

    out = Path(args.out) if args.out else None
    if args.kind == "model":
        path = figures.model_figure(args.participant or "P1", out)
    elif args.kind == "annotations":
        path = figures.annotations_figure(out)
    else:
        raise SystemExit(f"unknown figure {args.kind!r}")
    print(path)
    return 0


def parser() -> argparse.ArgumentParser:
    p = argparse.ArgumentParser(prog="wrist-bench", description=__doc__)
    sub = p.add_subparsers(dest="command", required=True)

    s = sub.add_parser("participants", help="list the known participants")
    s.add_argument("--folder", action="append", help="also register this participant folder")
    s.set_defaults(run=_participants)

    s = sub.add_parser("build", help="build (or load from cache) a participant model")
    s.add_argument("participant")
    s.add_argument("--json", action="store_true", help="print the build summary as JSON")
    s.add_argument("--no-cache", action="store_true", help="rebuild even if a cached model exists")
    s.add_argument("--folder", action="append", help="register this participant folder first")
    s.set_defaults(run=_build)

    s = sub.add_parser("figure", help="write a figure (PNG)")
    s.add_argument("kind", choices=["model", "annotations"])
    s.add_argument("participant", nargs="?")
    s.add_argument("--out", help="output PNG path")
    s.set_defaults(run=_figure)
    return p


def main(argv=None) -> int:
    args = parser().parse_args(argv)
    from wrist_env.errors import WristEnvError

    try:
        return args.run(args)
    except WristEnvError as exc:
        print(f"wrist-bench: error: {exc}", file=sys.stderr)
        return 2


if __name__ == "__main__":
    raise SystemExit(main())
