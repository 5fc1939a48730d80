"""The wrist problems in IOHexperimenter, and a benchmark run log in IOHanalyzer's format through ioh's logger."""

import json
from pathlib import Path

import numpy as np
import pytest

import wrist_env
from wrist_env.bench import RunKey, RunLog, benchmark
from wrist_env.bench.schema import X_COLUMNS
from wrist_env.cli import main

ioh = pytest.importorskip("ioh")
iohanalyzer = pytest.importorskip("wrist_env.bench.iohanalyzer")


def _dat_blocks(path):
    """The runs of an IOHanalyzer .dat file: one (n, columns) array per header line."""
    blocks, rows = [], None
    for line in path.read_text().splitlines():
        if line.startswith("evaluations"):
            header = line.split()
            rows = []
            blocks.append((header, rows))
        else:
            rows.append([float(v) for v in line.split()])
    return [(header, np.array(rows)) for header, rows in blocks]


def test_problem_is_the_calibration_cost_and_takes_ioh_loggers(built, tmp_path):
    from wrist_env import design
    from wrist_env.bench.calibrate import action
    from wrist_env.task import task

    built("P1")
    f = iohanalyzer.problem("P1")
    assert f.meta_data.name == "wrist-P1" and f.meta_data.n_variables == 22
    assert np.all(f.bounds.lb == -1.0) and np.all(f.bounds.ub == 1.0)
    logger = ioh.logger.Analyzer(root=str(tmp_path), folder_name="mine", algorithm_name="mine")
    f.attach_logger(logger)
    x = np.random.default_rng(0).uniform(-1, 1, (3, 22))
    values = [f(xi) for xi in x]
    logger.close()
    expected = [e.cost for e in task("P1", "calibrate").evaluate_batch([design.from_action(a) for a in action(x)])]
    np.testing.assert_allclose(values, expected, rtol=0, atol=1e-12)
    assert f.state.evaluations == 3 and f.state.current_best.y == min(values)
    assert (tmp_path / "mine" / f"IOHprofiler_f{f.meta_data.problem_id}_wrist-P1.json").is_file()


def test_a_benchmark_exports_in_iohanalyzer_format(built, tmp_path):
    built("P1")
    runs = tmp_path / "runs"
    report = benchmark(["P1"], ["random", "cmaes"], 2, 8, runs, workers=1, progress=False)
    assert not report.failed
    out = tmp_path / "ioh"
    assert main(["iohanalyzer", "--runs", str(runs), "--out", str(out)]) == 0
    assert main(["iohanalyzer", "--runs", str(runs), "--out", str(out)]) == 0  # replaces, not "cmaes-1"
    assert sorted(p.name for p in out.iterdir()) == ["cmaes", "random"]
    log = RunLog(runs).read()
    for optimizer in ("random", "cmaes"):
        (meta_path,) = (out / optimizer).glob("IOHprofiler_f*_wrist-P1.json")
        meta = json.loads(meta_path.read_text())
        assert meta["algorithm"]["name"] == optimizer and meta["maximization"] is False
        assert meta["function_name"] == "wrist-P1"
        (scenario,) = meta["scenarios"]
        assert scenario["dimension"] == 22 and len(scenario["runs"]) == 2
        blocks = _dat_blocks(out / optimizer / scenario["path"])
        assert len(blocks) == 2
        for seed, (run, (header, rows)) in enumerate(zip(scenario["runs"], blocks)):
            logged = log[(log.optimizer == optimizer) & (log.seed == seed)].sort_values("eval")
            costs = logged["cost"].to_numpy()
            assert run["evals"] == 8 and run["best"]["y"] == pytest.approx(costs.min(), abs=1e-9)
            assert run["best"]["evals"] == int(np.argmin(costs)) + 1
            np.testing.assert_allclose(run["best"]["x"], logged[list(X_COLUMNS)].to_numpy()[np.argmin(costs)])
            # the evaluations that improved on the logged costs, and the run's last (ioh closes a run with it)
            assert header[:2] == ["evaluations", "raw_y"] and len(header) == 2 + 22
            rows_at = sorted({i for i in range(8) if costs[i] < costs[:i].min(initial=np.inf)} | {7})
            assert rows[:, 0].astype(int).tolist() == [i + 1 for i in rows_at]
            np.testing.assert_allclose(rows[:, 1], costs[rows_at], atol=1e-9)
            np.testing.assert_allclose(
                rows[:, 2:], logged[list(X_COLUMNS)].to_numpy()[rows_at], atol=1e-6
            )  # ioh: 6 decimals


def test_an_empty_run_log_is_named(tmp_path):
    (tmp_path / "runs").mkdir()
    with pytest.raises(Exception, match="no evaluations are logged"):
        iohanalyzer.export(tmp_path / "runs", tmp_path / "out")


def test_the_docs_example_runs(built, tmp_path, monkeypatch, capsys):
    """The docs' ioh snippet (docs/benchmark.md), as printed there, from a fresh working directory."""
    built("P1")
    page = Path(wrist_env.__file__).resolve().parent.parent / "docs" / "benchmark.md"
    blocks = page.read_text().split("```python\n")[1:]
    (code,) = [b.split("```")[0] for b in blocks if "wrist_env.bench.iohanalyzer import problem" in b]
    monkeypatch.chdir(tmp_path)
    exec(compile(code, str(page), "exec"), {})
    assert float(capsys.readouterr().out.split()[-1]) > 0
    assert len(list((tmp_path / "runs" / "ioh").rglob("IOHprofiler_f*_DIM22.dat"))) == 1


def test_without_ioh_the_command_says_which_extra_to_install(tmp_path, monkeypatch):
    import importlib.util

    real = importlib.util.find_spec
    monkeypatch.setattr(importlib.util, "find_spec", lambda name, *a: None if name == "ioh" else real(name, *a))
    with pytest.raises(SystemExit, match=r"needs ioh.*\[ioh\]"):
        main(["iohanalyzer", "--runs", str(tmp_path), "--out", str(tmp_path / "out")])


def test_an_instance_is_ioh_instance_of_the_same_function(p1_instance_1):
    """As `ioh.get_problem(fid, instance, dim)`: instance 1 is the same function, its instance id 1, its value
    the cost on instance 1's calibration trial."""
    from wrist_env import design
    from wrist_env.task import task

    zero, one = iohanalyzer.problem("P1"), iohanalyzer.problem("P1", 1)
    assert (zero.meta_data.instance, one.meta_data.instance) == (0, 1)
    assert zero.meta_data.problem_id == one.meta_data.problem_id and one.meta_data.name == "wrist-P1"
    x = np.zeros(22)
    expected = task("P1", "calibrate", instance=1).evaluate(design.from_action(np.r_[x, np.ones(5)])).cost
    assert one(x) == pytest.approx(expected, rel=1e-12) and one(x) != pytest.approx(zero(x))


def test_the_export_carries_each_runs_instance(tmp_path):
    """Nothing simulated: a log of two instances' cells exports one problem, a run per (instance, seed)."""
    log = RunLog(tmp_path / "runs")
    for instance, seed in ((0, 0), (2, 2), (2, 5)):
        key = RunKey("P1", "random", seed, 4, instance)
        cost = np.arange(4.0) + 10 * instance + seed
        log.append(key, 0, 0, np.zeros((4, 22)), cost, [False] * 4, np.zeros((4, 12)))
    (folder,) = iohanalyzer.export(tmp_path / "runs", tmp_path / "ioh")
    (meta_path,) = folder.glob("IOHprofiler_f*_wrist-P1.json")
    (scenario,) = json.loads(meta_path.read_text())["scenarios"]
    assert [(r["instance"], r["best"]["y"]) for r in scenario["runs"]] == [(0, 0.0), (2, 22.0), (2, 25.0)]
