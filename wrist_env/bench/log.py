"""The benchmark's run log: append-only Parquet, one row per evaluation, resumable.

Layout of a run directory (`RunLog(root)`)::

    root/evals/part-<cell>-b00003-e000048-000064.parquet   one file per batch, as it finishes
    root/evals/cell-<cell>-n000300.parquet                 a finished cell's batches, compacted
    root/cells/<cell>.json                                 a finished cell's summary (calibrated design,
                                                           held-out cost, parameter recovery)
    root/locks/<cell>.lock                                 held (flock) while a process runs the cell
    root/damaged/                                          damaged or orphaned files moved aside by `repair`

It is a `wrist_env.runs.store.RunStore` (parts in `evals/`, records in
`cells/`): every file is written whole or not at all (temporary name, fsync,
`os.replace`), and a damaged file is a `StoreError` naming it. A row is one evaluation, its columns
`bench.schema.SCHEMA`.

Every evaluation file and summary records the participant's model and trials it was made on
(`wrist_env.runs.provenance`): a resume moves aside a cell made on others (`move_aside_stale`), the
leaderboard refuses one (`check_made_from`); and a file holds the cell its name says (`repair` and
`summary` check the rows' and the summary's key against the name: a cell copied under another name is
moved aside, not trusted).

No evaluation is logged twice: `append` refuses a batch whose file or eval
indices already exist, and `read` drops duplicate (run key, eval) rows (the
only way to get them is a crash between writing a compacted cell file and
removing its batch files, which the next compaction repairs).
"""

from __future__ import annotations

import os
import re
import time
from contextlib import AbstractContextManager
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np
import pyarrow as pa
from numpy.typing import ArrayLike

from wrist_env.bench.schema import (
    KEY_FIELDS,
    RERUN,
    RMSE_COLUMNS,
    SCHEMA,
    X_COLUMNS,
    RunKey,
    check_summary,
    describe_problem,
    summary_cell,
    summary_instance,
    with_instance,
)
from wrist_env.errors import DuplicateEvaluationError, IncompleteCellError, StoreError
from wrist_env.io import read_json
from wrist_env.runs import provenance
from wrist_env.runs.store import RunStore, read_parquet, remove_file, write_parquet

if TYPE_CHECKING:
    import pandas as pd

_PART = re.compile(r"^part-(?P<cell>.+)-b(?P<batch>\d+)-e(?P<start>\d+)-(?P<end>\d+)\.parquet$")
_CELL = re.compile(r"^cell-(?P<cell>.+)-n(?P<n>\d+)\.parquet$")


def _match(name: str) -> re.Match | None:
    return _PART.match(name) or _CELL.match(name)


def _span(m: re.Match) -> tuple[int, int]:
    """(first, end) evaluation of a batch or compacted cell file, from its name's match."""
    return (int(m["start"]), int(m["end"])) if "start" in m.groupdict() else (0, int(m["n"]))


class RunLog:
    """The run log under `root` (created on first write); its layout is the module's docstring.

    Parameters
    ----------
    root : str or Path
        The run directory (kept as ``root``, a Path; its `RunStore` is ``store``).
    """

    def __init__(self, root):
        self.root = Path(root)
        self.store = RunStore(self.root, parts="evals", records="cells")
        self.evals_dir = self.store.parts_dir
        self.locks_dir = self.store.locks_dir

    # writing

    def append(
        self,
        key: RunKey,
        batch: int,
        start: int,
        x: np.ndarray,
        cost: ArrayLike,
        failed: ArrayLike,
        rmse: np.ndarray,
        objective: ArrayLike | None = None,
        unsettled: ArrayLike | None = None,
        made_from: dict | None = None,
    ) -> Path:
        """Log one batch: evaluations start … start + k − 1 of `key`, atomically, never twice.

        x (k, 22) normalized materials; cost (k,); failed (k,); rmse (k, 12) in `RMSE_COLUMNS` order;
        objective (k,) the values told to the calibrator (default: the cost); unsettled (k,) frames that
        did not settle per evaluation, None where it failed (default: all null); made_from: the
        participant's `provenance.of_participant`, recorded in the file's metadata.
        """
        x = np.atleast_2d(np.asarray(x, dtype=np.float64))
        k = len(x)
        cost = np.asarray(cost, dtype=np.float64).reshape(k)
        failed = np.asarray(failed, dtype=bool).reshape(k)
        rmse = np.asarray(rmse, dtype=np.float64).reshape(k, len(RMSE_COLUMNS))
        if x.shape[1] != len(X_COLUMNS):
            raise ValueError(f"x must have {len(X_COLUMNS)} columns, but got {x.shape}")
        logged = self.logged_range(key)
        if start != logged:
            raise DuplicateEvaluationError(
                f"{key.name}: batch {batch} starts at evaluation {start}, but {logged} evaluations are logged "
                f"(evaluations must be logged once, in order)"
            )
        existing = list(self.evals_dir.glob(f"part-{key.name}-b{batch:05d}-*.parquet"))
        if existing:
            raise DuplicateEvaluationError(f"{key.name}: batch {batch} is already logged ({existing[0].name})")
        now = time.time()
        columns = {
            "participant": [key.participant] * k,
            "optimizer": [key.optimizer] * k,
            "seed": [key.seed] * k,
            "budget": [key.budget] * k,
            "instance": [key.instance] * k,
            "eval": list(range(start, start + k)),
            "batch": [batch] * k,
            "time": [now] * k,
        }
        columns.update({c: x[:, i] for i, c in enumerate(X_COLUMNS)})
        columns["cost"] = cost
        columns["failed"] = failed
        columns.update({c: rmse[:, i] for i, c in enumerate(RMSE_COLUMNS)})
        columns["objective"] = cost if objective is None else np.asarray(objective, dtype=np.float64).reshape(k)
        columns["unsettled"] = [None] * k if unsettled is None else [None if u is None else int(u) for u in unsettled]
        if len(columns["unsettled"]) != k:
            raise ValueError(f"unsettled must have {k} entries, but got {len(columns['unsettled'])}")
        table = pa.Table.from_pydict(columns, schema=SCHEMA)
        if made_from is not None:
            table = provenance.with_provenance(table, made_from)
        return self.store.write_part(f"part-{key.name}-b{batch:05d}-e{start:06d}-{start + k:06d}", table)

    def compact(self, key: RunKey) -> Path | None:
        """Merge a cell's batch files into one file (then remove them); the rows are unchanged."""
        frame = self.read_cell(key)
        if frame is None:
            return None
        path = self.evals_dir / f"cell-{key.name}-n{len(frame):06d}.parquet"
        table = pa.Table.from_pandas(frame, schema=SCHEMA, preserve_index=False)
        recorded = [provenance.read_provenance(p, RERUN) for p in self._files(key)]
        if recorded and recorded[0] is not None and all(r == recorded[0] for r in recorded):
            table = provenance.with_provenance(table, recorded[0])  # kept where the files agree on it
        write_parquet(path, table)
        for p in self._files(key):
            if p != path:
                remove_file(p)
        return path

    def write_summary(self, key: RunKey, summary: dict, made_from: dict | None = None) -> Path:
        """Write a finished cell's summary, with the provenance it was made on (`made_from`) if given."""
        return self.store.write_record(key.name, summary | ({} if made_from is None else {provenance.FIELD: made_from}))

    def logged(self, key: RunKey) -> bool:
        """Whether anything of the cell is in the log (an evaluation file or its summary)."""
        return bool(self._files(key)) or self.store.record_path(key.name).is_file()

    def move_aside_stale(self, key: RunKey, made_from: dict) -> int:
        """Move to `damaged/` every file of the cell (its evaluations and its summary) if any of them was
        made on another model or trials than `made_from` (`provenance.of_participant`), or records none:
        the cell then runs again from scratch (a replay of another model's evaluations would calibrate on
        them). Returns the files moved."""
        summary_path = self.store.record_path(key.name)
        recorded = [(p, provenance.read_provenance(p, RERUN)) for p in self._files(key)]
        if summary_path.is_file():
            try:
                data = read_json(summary_path, "cell summary")
            except StoreError:
                data = None  # unreadable: `repair` moves it aside
            if isinstance(data, dict):
                recorded.append((summary_path, data.get(provenance.FIELD)))
        changed = next(((p, d) for p, r in recorded if (d := provenance.differences(r, made_from))), None)
        if changed is None:
            return 0
        why = f"made on another model or trials of {key.problem} ({changed[1]}); the cell runs again"
        moved = sum(
            self.store.quarantine(p, why if p == changed[0] else f"{why} (as {changed[0].name})") is not None
            for p, _ in recorded
        )
        return moved

    def check_made_from(self, made_from: dict[tuple[str, int], dict]) -> None:
        """`StoreError` naming the first finished cell's summary made on another model or trials than
        `made_from` ({(participant, instance): `provenance.of_participant`}) records (the leaderboard's check)."""
        for name in self.store.record_names():
            path = self.store.record_path(name)
            summary = self.store.read_record(name, advice=RERUN)
            problem = (summary.get("participant"), summary_instance(summary)) if isinstance(summary, dict) else None
            today = made_from.get(problem)
            changed = "" if today is None else provenance.differences(summary.get(provenance.FIELD), today)
            if changed:
                raise StoreError(
                    f"{path}: this cell was calibrated on another model or trials of {describe_problem(*problem)} "
                    f"({changed}); {RERUN} on today's model"
                )

    def lock(self, key: RunKey) -> AbstractContextManager[None]:
        """Hold the cell's lock (an flock, released when the process dies) while running it."""
        return self.store.lock(key.name, what=f"cell {key.name}")

    # repairing

    def repair(self) -> int:
        """Make the log consistent before a run: remove temporary files; move to `damaged/` every
        unreadable or changed Parquet file and every batch after a gap (a deleted file), each with the
        later batches of its cell, so the cell resumes from the gap; and every unreadable, incomplete
        or changed summary and every summary whose evaluations are not all logged (those cells run
        again, by replay where their evaluations are logged). Returns the files moved."""
        self.store.clean()
        moved = 0
        for name, _ in self.store.damaged_parts(SCHEMA):
            path = self.store.part_path(name)
            m = _match(path.name)
            if m is not None:
                moved += self._drop_from(path, "damaged Parquet file, its evaluations are re-simulated")
        for path in self._files():
            if path.exists() and (why := self._misnamed(path)):
                moved += self._drop_from(path, why)
        for files in self._by_cell().values():
            end = 0
            for start, stop, path in files:
                if start > end:
                    reason = f"evaluations {end}…{start - 1} of its cell are missing (a file deleted?), re-simulated"
                    moved += self._drop_from(path, reason)
                    break
                end = max(end, stop)
        return moved + self._repair_summaries()

    def _misnamed(self, path: Path) -> str:
        """Why the evaluations in `path` are not the ones its name says (another cell's rows, or other
        evaluation numbers: a copy under another name), or "" if they are (or it is unreadable: damage)."""
        m = _match(path.name)
        try:
            cols = read_parquet(path, SCHEMA, columns=[*KEY_FIELDS, "eval"], advice=RERUN).to_pydict()
        except StoreError:
            return ""
        cells = {summary_cell(dict(zip(KEY_FIELDS, k))) for k in zip(*(cols[f] for f in KEY_FIELDS))}
        first, end = _span(m)
        if cells != {m["cell"]}:
            return f"holds evaluations of {', '.join(sorted(cells)) or 'no cell'}, not of {m['cell']} (a copy?), re-simulated"
        if sorted(cols["eval"]) != list(range(first, end)):
            return f"holds other evaluations than {first}…{end - 1} its name says (a copy?), re-simulated"
        return ""

    def _by_cell(self) -> dict[str, list[tuple[int, int, Path]]]:
        """{cell name: [(first eval, end eval, file)] sorted}, from the file names."""
        out: dict[str, list[tuple[int, int, Path]]] = {}
        for p in self._files():
            m = _match(p.name)
            out.setdefault(m["cell"], []).append((*_span(m), p))
        return {cell: sorted(files) for cell, files in out.items()}

    def _drop_from(self, path: Path, reason: str) -> int:
        """Move `path` and every later file of its cell to `damaged/`; returns how many moved."""
        m = _match(path.name)
        first, moved = _span(m)[0], 0
        for start, _, p in self._by_cell().get(m["cell"], []):
            if p == path or start >= first:
                why = reason if p == path else f"follows {path.name} in its cell, re-simulated"
                moved += self.store.quarantine(p, why) is not None
        return moved

    def _repair_summaries(self) -> int:
        """Move aside every summary `summary` would refuse (the cell runs again); returns how many."""
        progress, moved = self.progress(), 0
        for name in self.store.record_names():
            try:
                self._finished(name, progress)
            except IncompleteCellError as e:
                reason = f"{str(e).split(': ', 1)[1].split('; ')[0]}; the cell runs again"
                moved += self.store.quarantine(self.store.record_path(name), reason) is not None
            except StoreError as e:
                reason = f"{str(e).split(': ', 1)[-1].split('; ')[0]}; the cell runs again (by replay)"
                moved += self.store.quarantine(self.store.record_path(name), reason) is not None
        return moved

    # reading

    def _files(self, key: RunKey | None = None) -> list[Path]:
        if not self.evals_dir.is_dir():
            return []
        pattern = "*.parquet" if key is None else f"*-{key.name}-*.parquet"
        out = []
        for p in sorted(self.evals_dir.glob(pattern)):
            m = _match(p.name)
            if m and (key is None or m["cell"] == key.name):
                out.append(p)
        return out

    def _table(self, files) -> pa.Table:
        """The rows of `files` (`SCHEMA`; the instance of a file written before instances is 0)."""
        return pa.concat_tables([with_instance(read_parquet(p, SCHEMA, advice=RERUN)) for p in files])

    def read(self, *, dedupe: bool = True) -> pd.DataFrame:
        """Every logged evaluation as a pandas DataFrame (sorted by run key and eval), duplicates dropped."""
        import pandas as pd

        files = self._files()
        if not files:
            return pd.DataFrame({f.name: pd.Series(dtype=f.type.to_pandas_dtype()) for f in SCHEMA})
        frame = self._table(files).to_pandas()
        if dedupe:
            frame = frame.drop_duplicates(subset=list(KEY_FIELDS) + ["eval"], keep="first")
        return frame.sort_values(list(KEY_FIELDS) + ["eval"], kind="stable").reset_index(drop=True)

    def read_cell(self, key: RunKey) -> pd.DataFrame | None:
        """The cell's rows (DataFrame sorted by eval, duplicates dropped), or None if nothing is logged."""
        files = self._files(key)
        if not files:
            return None
        frame = self._table(files).to_pandas()
        frame = frame[
            (frame.participant == key.participant)
            & (frame.optimizer == key.optimizer)
            & (frame.seed == key.seed)
            & (frame.budget == key.budget)
            & (frame.instance == key.instance)
        ]
        frame = frame.drop_duplicates(subset=["eval"], keep="first").sort_values("eval", kind="stable")
        frame = frame.reset_index(drop=True)
        if not np.array_equal(frame["eval"].to_numpy(), np.arange(len(frame))):
            raise StoreError(
                f"{self.evals_dir}: the logged evaluations of {key.name} are not 0 … n−1 "
                f"({frame['eval'].tolist()[:20]}…); {RERUN}"
            )
        return frame

    def logged_range(self, key: RunKey) -> int:
        """How many evaluations of the cell are logged (from the file names; cheap)."""
        return self.progress().get(key.name, 0)

    def progress(self) -> dict[str, int]:
        """{cell name: evaluations logged}, from the file names alone (for progress bars)."""
        out: dict[str, int] = {}
        if not self.evals_dir.is_dir():
            return out
        with os.scandir(self.evals_dir) as it:
            for entry in it:
                m = _PART.match(entry.name)
                if m:
                    out[m["cell"]] = max(out.get(m["cell"], 0), int(m["end"]))
                    continue
                m = _CELL.match(entry.name)
                if m:
                    out[m["cell"]] = max(out.get(m["cell"], 0), int(m["n"]))
        return out

    def summary(self, key: RunKey) -> dict | None:
        """The summary of a finished cell, or None if the cell has not finished.

        `IncompleteCellError` if the summary counts more evaluations than are logged; `StoreError` if
        it is damaged (both name the file; a rerun of the benchmark repairs them)."""
        return self._finished(key.name, self.progress())

    def _finished(self, name: str, progress: dict) -> dict | None:
        summary = self.store.read_record(name, advice=RERUN)
        if summary is None:
            return None
        check_summary(self.store.record_path(name), summary)
        named = summary_cell(summary)
        if named != name:
            raise StoreError(
                f"{self.store.record_path(name)}: holds the summary of cell {named}, not of {name} (a copy under "
                f"another name?); {RERUN}"
            )
        n = summary["nfev"]
        if progress.get(name, 0) < n:
            raise IncompleteCellError(
                f"{self.store.record_path(name)}: the cell finished with {n} evaluations, but "
                f"{progress.get(name, 0)} are logged in {self.evals_dir}; {RERUN}"
            )
        return summary

    def summaries(self) -> list[dict]:
        """The summaries of every finished cell (errors as `summary`)."""
        progress = self.progress()
        return [self._finished(name, progress) for name in self.store.record_names()]
