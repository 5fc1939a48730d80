"""Build the built-in participants' models from scratch and ship them with the package.

Writes `wrist_env/participants/data/<P>/model.npz` + `model.json` for P1–P3 (default build
parameters), so that a fresh install skips the ~40 s build per participant:
`registry.load_model` reads a shipped model when its source hash is the one it would build
(`builtin.SHIPPED_MODEL`), and builds otherwise. A slow test rebuilds P1 and compares. Run after
any change to the builder, the template or the built-ins' data (`experiments/regenerate.py` does).
"""

from __future__ import annotations

import time
from pathlib import Path

from wrist_env.participants import builtin
from wrist_env.participants.registry import load_model

DATA = Path(__file__).resolve().parents[2] / "wrist_env" / "participants" / "data"


def main() -> None:
    for name in builtin.BUILTIN:
        start = time.perf_counter()
        model = load_model(name, cache=False)
        model.save(DATA / name / builtin.SHIPPED_MODEL)
        size = sum((DATA / name / f"{builtin.SHIPPED_MODEL}{s}").stat().st_size for s in (".npz", ".json"))
        print(
            f"{name}: {model.source_hash}, built in {time.perf_counter() - start:.0f} s, {size / 1e6:.1f} MB",
            flush=True,
        )


if __name__ == "__main__":
    main()
