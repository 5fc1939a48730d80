"""Build the built-in participants' models from scratch and ship them with the package.

Writes `wrist_env/participants/data/<P>/model.npz` + `model.json` for P1–P3 (default build
parameters, `registry.build_params`), so that a fresh install skips the ~40 s build per participant:
`registry.load_model` reads a shipped model when its source hash is the one it would build
(`builtin.SHIPPED_MODEL`), and builds otherwise. A slow test rebuilds P1 and compares. Run after
any change to the builder, the template or the built-ins' data (`experiments/regenerate.py` does).

A shipped model whose source hash is the one a build would have (same bones, build parameters, builder
and annotation versions: `builder.digest.source_hash`) is kept as it is (`--force` rebuilds it): a rebuild
is not reproducible to the bit (the morph's round-off, ~1e-12 mm, grows to ~0.1 mm of cartilage thickness
in `builder/cartilage.py`), and every committed result was made on the shipped model, so rebuilding an
unchanged one would move them for nothing.
"""

from __future__ import annotations

import argparse
import time
from pathlib import Path

from wrist_env.builder.digest import source_hash
from wrist_env.participants import builtin
from wrist_env.participants.registry import bones, build_params, load_model

DATA = Path(__file__).resolve().parents[2] / "wrist_env" / "participants" / "data"


def main() -> None:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--force", action="store_true", help="rebuild every model, even one whose source hash is unchanged")
    force = p.parse_args().force
    for name in builtin.BUILTIN:
        start = time.perf_counter()
        wanted = source_hash(name, bones(name), build_params(name))
        if not force and builtin.shipped_source_hash(name) == wanted:
            print(f"{name}: {wanted}, unchanged (kept; --force rebuilds it)", flush=True)
            continue
        model = load_model(name, cache=False)
        model.save(DATA / name / builtin.SHIPPED_MODEL)
        size = sum((DATA / name / f"{builtin.SHIPPED_MODEL}{s}").stat().st_size for s in (".npz", ".json"))
        print(
            f"{name}: {model.source_hash}, built in {time.perf_counter() - start:.0f} s, {size / 1e6:.1f} MB",
            flush=True,
        )


if __name__ == "__main__":
    main()
