import json
import os
import subprocess
import sys

import numpy as np
import pytest

from wrist_env.cli import main


def test_participants_lists_the_builtins(capsys):
    assert main(["participants"]) == 0
    out = capsys.readouterr().out
    for name in ("P1", "P2", "P3"):
        assert name in out
    assert "synthetic" in out and "grip" in out


def test_build_json_has_the_summary_fields(capsys, built):
    built("P1")
    assert main(["build", "P1", "--json"]) == 0
    summary = json.loads(capsys.readouterr().out)
    for key in (
        "build_seconds",
        "morph_error_mm",
        "fibres",
        "cartilage_thickness_mm",
        "joint_space_mm",
        "contact_law_r2",
    ):
        assert key in summary, key
    assert summary["fibres"]["SLIL_d"] == 7 and summary["fibres"]["UL"] == 3
    assert set(summary["cartilage_thickness_mm"]["radioscaphoid"]) == {"min", "mean", "max"}
    assert summary["build_seconds"] > 0


def test_unknown_participant_is_a_clear_error(capsys):
    assert main(["build", "P9"]) == 2
    assert "unknown participant 'P9'" in capsys.readouterr().err


def test_simulate_json_has_every_frame_and_the_wall_time(capsys, built):
    import math

    built("P1")
    assert main(["simulate", "P1", "--motion", "idealized", "--design", "population", "--frames", "5", "--json"]) == 0
    out = json.loads(capsys.readouterr().out)
    for key in ("participant", "motion", "design", "wall_seconds", "compile_seconds", "status", "message", "frames"):
        assert key in out, key
    assert out["status"] == 0 and out["message"] == "ok" and out["wall_seconds"] > 0 and out["compile_seconds"] is None
    assert out["n_frames"] == len(out["frames"]) == 5
    assert [f["capitate_angle_deg"] for f in out["frames"]] == [40.0, 20.0, 0.0, -20.0, -40.0]

    def numbers(x):
        if isinstance(x, dict):
            return [v for y in x.values() for v in numbers(y)]
        if isinstance(x, list):
            return [v for y in x for v in numbers(y)]
        return [x]

    for frame in out["frames"]:
        for key in (
            "poses",
            "contact",
            "ligament_force_n",
            "kinetic_energy_nmm",
            "internal_energy_nmm",
            "residual",
            "steps",
            "settled",
        ):
            assert key in frame, key
        values = numbers({k: v for k, v in frame.items()})
        assert all(isinstance(v, (int, float)) and math.isfinite(v) for v in values)
        assert set(frame["contact"]["radioscaphoid"]) == {
            "mean_pressure_mpa",
            "peak_pressure_mpa",
            "area_mm2",
            "force_n",
        }


def test_simulate_picks_the_solver(capsys, built):
    """--solver diagonal: the same sweep in more steps than the default (block mass) solver's, every
    frame settled, the scaphoid's and lunate's flexion within 0.1° of each other; an unknown solver is a
    usage error."""
    built("P1")
    runs = {}
    for solver in ("diagonal", "default"):
        argv = ["simulate", "P1", "--frames", "5", "--json", "--solver", solver]
        assert main(argv) == 0
        runs[solver] = json.loads(capsys.readouterr().out)["frames"]
    steps = {k: sum(f["steps"] for f in v) for k, v in runs.items()}
    assert steps["default"] < steps["diagonal"], steps
    for a, b in zip(runs["diagonal"], runs["default"]):
        assert b["settled"]
        for bone in ("scaphoid", "lunate"):
            assert abs(a["rotation_deg"][bone][0] - b["rotation_deg"][bone][0]) < 0.1, (bone, a, b)
    assert main(["simulate", "P1", "--solver", "implicit"]) == 2  # argparse's refusal: one line, exit 2


def test_simulate_drives_a_trial_as_the_task_does(capsys, built):
    """`simulate --motion calibrate` drives the capitate through the participant's calibration trial with the driver
    the task scores (`drivers.for_motion`, one map for both): the same frames and the same scaphoid poses as
    `task("P1").evaluate`; --frames is refused for a trial (it has its own)."""
    import numpy as np

    from wrist_env import design
    from wrist_env.model import BONES
    from wrist_env.task import task

    built("P1")
    assert main(["simulate", "P1", "--motion", "calibrate", "--json"]) == 0
    frames = json.loads(capsys.readouterr().out)["frames"]
    result = task("P1", "calibrate").evaluate(design.population()).result
    assert len(frames) == len(result.poses)
    scaphoid = np.array([f["poses"]["scaphoid"] for f in frames])
    assert np.allclose(scaphoid, result.poses[:, BONES.index("scaphoid")], atol=1e-9)
    assert main(["simulate", "P1", "--motion", "validate", "--frames", "5"]) == 2
    assert "has its trial's" in capsys.readouterr().err


def test_simulate_static_truth_and_design_file(capsys, built, tmp_path):
    from wrist_env import design
    from wrist_env.participants.builtin import truth

    built("P1")
    assert main(["simulate", "P1", "--motion", "static", "--design", "truth", "--frames", "2", "--warm-up"]) == 0
    text = capsys.readouterr().out
    assert "scaphoid" in text and "RS mean MPa" in text and "status: ok" in text and "warm-up" in text
    assert len([line for line in text.splitlines() if line.strip()[:1].isdigit()]) == 2

    path = tmp_path / "d.json"
    path.write_text(json.dumps(truth("P1").as_dict()))
    assert main(["simulate", "P1", "--motion", "static", "--design", str(path), "--frames", "2", "--json"]) == 0
    from_file = json.loads(capsys.readouterr().out)
    assert main(["simulate", "P1", "--motion", "static", "--design", "truth", "--frames", "2", "--json"]) == 0
    assert json.loads(capsys.readouterr().out)["frames"] == from_file["frames"]
    assert from_file["frames"][0]["capitate_angle_deg"] is None

    path.write_text(json.dumps({"stiffness": 1}))
    assert main(["simulate", "P1", "--design", str(path)]) == 2
    assert "missing variables" in capsys.readouterr().err
    assert main(["simulate", "P1", "--design", "nonsense"]) == 2
    assert "'population', 'truth' or a JSON file" in capsys.readouterr().err
    assert design.population()  # the population design needs no file


def test_figure_commands_write_pngs(capsys, built, tmp_path):
    built("P1")
    for kind in ("pressure", "kinematics"):
        out = tmp_path / f"{kind}.png"
        assert main(["figure", kind, "P1", "--out", str(out)]) == 0
        assert capsys.readouterr().out.strip() == str(out)
        assert out.stat().st_size > 10_000 and out.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"


@pytest.mark.slow
def test_the_animation_is_a_gif_of_the_sweep_whose_frames_differ(capsys, built, tmp_path):
    from PIL import Image

    built("P1")
    out = tmp_path / "sweep.gif"
    assert main(["figure", "animation", "P1", "--out", str(out)]) == 0
    assert capsys.readouterr().out.strip() == str(out)
    with Image.open(out) as gif:
        assert gif.format == "GIF" and gif.n_frames == 17
        frames = []
        for k in (0, 8, 16):
            gif.seek(k)
            frames.append(np.asarray(gif.convert("L"), dtype=float))
    assert np.abs(frames[0] - frames[2]).mean() > 1.0  # the bones moved between full flexion and extension
    assert np.abs(frames[0] - frames[1]).mean() > 0.5


def test_evaluate_json_truth_beats_population(capsys, built):
    import math

    built("P1")
    out = {}
    for spec in ("population", "truth"):
        assert main(["evaluate", "P1", "--design", spec, "--json"]) == 0
        out[spec] = json.loads(capsys.readouterr().out)
    for spec, o in out.items():
        for key in ("participant", "motion", "design", "failed", "status", "cost", "error_p75", "rmse", "wall_seconds"):
            assert key in o, key
        assert (o["participant"], o["motion"], o["design"]) == ("P1", "calibrate", spec)
        assert o["failed"] is False and o["status"] == "ok" and o["wall_seconds"] > 0
        for name in ("error_p75", "rmse"):
            assert set(o[name]) == {"scaphoid", "lunate"}
            values = [v for bone in o[name].values() for v in bone.values()]
            assert len(values) == 12 and all(isinstance(v, float) and math.isfinite(v) and v >= 0 for v in values)
    assert 0 < out["truth"]["cost"] < out["population"]["cost"]


def test_evaluate_table_and_design_file(capsys, built, tmp_path):
    from wrist_env.participants.builtin import truth

    built("P1")
    assert main(["evaluate", "P1", "--design", "truth", "--json"]) == 0
    at_truth = json.loads(capsys.readouterr().out)["cost"]
    path = tmp_path / "d.json"
    path.write_text(json.dumps(truth("P1").as_dict()))
    assert main(["evaluate", "P1", "--design", str(path), "--json"]) == 0
    assert json.loads(capsys.readouterr().out)["cost"] == at_truth
    assert main(["evaluate", "P1", "--design", "truth"]) == 0
    text = capsys.readouterr().out
    assert "p75 error" in text and "RMSE" in text and f"cost {at_truth:.4f}" in text
    rows = [line.split() for line in text.splitlines() if line.startswith(("scaphoid", "lunate"))]
    assert len(rows) == 12 and {r[-1] for r in rows} == {"mm", "deg"}
    assert main(["evaluate", "P9"]) == 2
    assert "unknown participant 'P9'" in capsys.readouterr().err


def test_every_participant_command_takes_folder_once_and_registers_it(tmp_path):
    from wrist_env.cli import parser

    p = parser()
    sub = next(a for a in p._actions if a.dest == "command")
    with_folder = [name for name, s in sub.choices.items() if any("--folder" in a.option_strings for a in s._actions)]
    assert set(with_folder) >= {
        "participants",
        "build",
        "simulate",
        "evaluate",
        "validate",
        "figure",
        "calibrate",
        "benchmark",
        "leaderboard",
        "montecarlo",
    }
    assert (
        main(["participants", "--folder", str(tmp_path / "missing")]) == 2
    )  # registered (and refused) before the command


def test_an_unknown_calibrator_is_one_line_and_exit_2(capsys):
    assert main(["calibrate", "P1", "--optimizer", "nope", "--budget", "2"]) == 2
    err = capsys.readouterr().err
    assert err.startswith("wrist-bench: error: unknown optimizer 'nope'") and len(err.strip().splitlines()) == 1


def test_no_command_writes_into_the_committed_results_by_default():
    """User commands write under runs/ (git-ignored) unless told otherwise; leaderboards/ and
    experiments/figures/ are written only by experiments/regenerate.py, with explicit paths."""
    from wrist_env.cli import parser

    sub = next(a for a in parser()._actions if a.dest == "command")
    outputs = {}
    for name, command in sub.choices.items():
        for action in command._actions:
            if action.dest in ("out", "leaderboard") and action.default is not None:
                outputs[f"{name} --{action.dest}"] = action.default
    assert outputs, "no output defaults found"
    assert all(str(d).startswith("runs/") for d in outputs.values()), outputs
    env = {k: v for k, v in os.environ.items() if k != "WRIST_ENV_FIGURES"}
    code = "from wrist_env.figures.draw import FIGURES; print(FIGURES.as_posix())"
    out = subprocess.run([sys.executable, "-c", code], env=env, capture_output=True, text=True, check=True)
    assert out.stdout.strip() == "runs/figures"


@pytest.mark.slow
def test_export_build_evaluate_and_make_an_env_from_a_clean_folder(tmp_path, capsys):
    """`export` writes a folder the folder loader reads back (P1's five bones and trials); `build`,
    `evaluate` and `register_participant` run on a clean folder. The folder built is tests/envs'
    "U1" (warped template bones, P1's unresisted trial), whose model the session builds once into its
    cache (the cache key is its bones and name), not a second folder model (a minute of CI)."""
    import importlib.util
    from pathlib import Path

    import gymnasium as gym

    import wrist_env
    from wrist_env.participants import registry
    from wrist_env.participants.folder import load_participant_folder

    folder = tmp_path / "my_wrist"
    assert main(["export", "P1", str(folder)]) == 0
    assert (folder / "participant.toml").is_file() and len(list((folder / "bones").glob("*.stl"))) == 5
    assert main(["export", "P1", str(folder)]) == 2  # not over a folder already written
    assert "not empty" in capsys.readouterr().err
    exported = load_participant_folder(folder)
    assert exported.name == "my_wrist" and set(exported.trials) == set(registry.trials("P1"))

    spec = importlib.util.spec_from_file_location(
        "_register_tests", Path(__file__).parent / "envs" / "test_register.py"
    )
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    u1 = module.make_folder(tmp_path / "u1", "U1", validate=False)
    assert main(["build", "U1", "--folder", str(u1)]) == 0
    assert "U1: built in" in capsys.readouterr().out
    assert main(["evaluate", "U1", "--folder", str(u1), "--json"]) == 0
    out = json.loads(capsys.readouterr().out)
    assert out["failed"] is False and 0 < out["cost"] < 100
    ids = wrist_env.register_participant(u1)
    assert "wrist_env/Calibrate-U1-v0" in ids
    env = gym.make("wrist_env/Calibrate-U1-v0")
    env.reset(seed=0)
    from wrist_env import design

    _, reward, terminated, _, info = env.step(design.to_action(design.population()).astype(np.float32))
    assert terminated and reward == -out["cost"] and not info["failed"]


ONE_LINE_USAGE_ERRORS = {
    "calibrate seed -2": (["calibrate", "P1", "--seed", "-2"], r"seed must be an integer in \[0, 4,294,967,295\]"),
    "calibrate budget 0": (["calibrate", "P1", "--budget", "0"], r"budget must be an integer in \[1, 1,000,000\]"),
    "benchmark budget 0": (["benchmark", "--budget", "0"], r"budget must be an integer in \[1, 1,000,000\]"),
    "benchmark seeds 0": (["benchmark", "--seeds", "0"], r"seeds must be an integer in \[1, 10,000\]"),
    "benchmark instances 0": (["benchmark", "--instances", "0"], r"instances must be an integer in \[1, 10,000\]"),
    "benchmark instances 3-1": (["benchmark", "--instances", "3-1"], r"instances a-b must have a <= b, but got '3-1'"),
    "benchmark instances list": (["benchmark", "--instances", "1,x"], r"instance must be an integer .*but got 'x'"),
    "benchmark instances twice": (["benchmark", "--instances", "2,2"], r"instances must not repeat, but got \[2, 2\]"),
    "calibrate instance -1": (["calibrate", "P1", "--instance", "-1"], r"instance must be an integer in \[0, 10,000\]"),
    "workers -3": (["benchmark", "--workers", "-3"], r"workers must be an integer in \[1, 256\], but got -3"),
    "workers 0": (["benchmark", "--workers", "0"], r"workers must be an integer in \[1, 256\], but got 0"),
    "threads 0": (["benchmark", "--threads", "0"], r"threads must be an integer in \[1, 256\], but got 0"),
    "participants twice": (
        ["benchmark", "--participants", "P1", "P1", "--optimizers", "random"],
        r"participants must not repeat, but got \['P1', 'P1'\] \(P1 more than once\)",
    ),
    "optimizers twice": (["benchmark", "--optimizers", "random", "random"], r"optimizers must not repeat"),
    "montecarlo n huge": (["montecarlo", "P1", "--n", "10000000000"], r"n must be an integer in \[1, 1,000,000\]"),
    "montecarlo workers -1": (["montecarlo", "P1", "--workers", "-1"], r"workers must be an integer in \[0, 256\]"),
    "leaderboard no log": (["leaderboard", "--runs", "/nonexistent/log"], r"no run log at /nonexistent/log"),
    "simulate frames 3e6": (
        ["simulate", "P1", "--frames", "3000000"],
        r"--frames: frames .* \[1, 10,000\], but got 3000000",
    ),
    "simulate frames 1e8": (["simulate", "P1", "--frames", "1e8"], r"--frames: frames .* \[1, 10,000\], but got '1e8'"),
    "simulate frames 0": (["simulate", "P1", "--frames", "0"], r"--frames: frames .* \[1, 10,000\], but got 0"),
    "simulate flexion nan": (
        ["simulate", "P1", "--flexion", "nan"],
        r"--flexion: .* finite number in \[-90, 90\].* nan",
    ),
    "simulate extension inf": (["simulate", "P1", "--extension", "inf"], r"--extension: .* \[-90, 90\].* inf"),
    "sensitivity n 2e6": (["sensitivity", "P1", "--n", "2000000"], r"--n: n must be an integer in \[2, 4,096\]"),
    "sensitivity n 0": (["sensitivity", "P1", "--n", "0"], r"--n: n must be an integer in \[2, 4,096\].* got 0"),
    "sensitivity seed -1": (["sensitivity", "P1", "--seed", "-1"], r"--seed: seed .* \[0, 4,294,967,295\], but got -1"),
    "sensitivity sobol n 3": (
        ["sensitivity", "P1", "--method", "sobol", "--n", "3"],
        r"sobol needs n a power of 2 .* at least 2, but got 3: the nearest are 2 and 4",
    ),
    "posterior walkers 5e6": (["posterior", "P1", "--walkers", "5000000"], r"--walkers: walkers .* \[44, 4,096\]"),
    "posterior steps 4": (["posterior", "P1", "--steps", "4"], r"--steps: steps must be an integer in \[8, 100,000\]"),
    "validate load nan": (["validate", "P1", "--load", "nan"], r"--load: load .* finite number in \[0, 1,000\].* nan"),
    "validate load -5": (["validate", "P1", "--load", "-5"], r"--load: load .* \[0, 1,000\] .*but got -5.0"),
    "validate fossa sweep nan": (
        ["validate", "P1", "--fossa-sweep", "nan", "nan"],
        r"--fossa-sweep: fossa sweep half-range .* \[0, 90\].* nan",
    ),
    "validate fossa sweep -5": (["validate", "P1", "--fossa-sweep", "-5", "10"], r"--fossa-sweep: .*\[0, 90\]"),
    "montecarlo-report max-runs 0": (["montecarlo-report", "--max-runs", "0"], r"--max-runs: max_runs .* \[7, "),
    "montecarlo-report max-runs -5": (["montecarlo-report", "--max-runs", "-5"], r"max_runs .* \[7, .*got -5"),
    "montecarlo-report max-runs 1": (
        ["montecarlo-report", "--max-runs", "1"],
        r"max_runs .* \[7, .*5 tear indicators and the variance between runs need 7 runs.*got 1",
    ),
    "montecarlo tear-probability nan": (["montecarlo", "P1", "--tear-probability", "nan"], r"tear probability .* nan"),
    "montecarlo batch 1e6": (["montecarlo", "P1", "--batch", "1000000"], r"--batch: batch .* \[1, 4,096\]"),
    "benchmark budget 1e9": (["benchmark", "--budget", "1000000000"], r"--budget: budget .* \[1, 1,000,000\]"),
}


@pytest.mark.parametrize("argv, message", ONE_LINE_USAGE_ERRORS.values(), ids=ONE_LINE_USAGE_ERRORS)
def test_usage_errors_are_one_line_and_exit_2(argv, message, capsys, tmp_path):
    """Every size and value a user types is refused with its option, value and limit (issue 53), exit 2,
    before anything is loaded or written (no model here: a load would take seconds and write nothing)."""
    import re

    out = [] if argv[0] in ("calibrate", "leaderboard") else ["--out", str(tmp_path / "out")]
    assert main(argv + out) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and err.startswith("wrist-bench: error: ") and re.search(message, err), err
    assert not (tmp_path / "out").exists()


def _file(tmp_path):
    (tmp_path / "a-file").write_text("")
    return tmp_path / "a-file"


OUT_THE_SYSTEM_REFUSES = {
    "montecarlo into a file": lambda t: ["montecarlo", "P1", "--n", "2", "--no-progress", "--out", str(_file(t))],
    "benchmark into a file": lambda t: ["benchmark", "--optimizers", "random", "--no-progress", "--out", str(_file(t))],
    "leaderboard under /proc": lambda t: ["leaderboard", "--runs", str(t), "--out", "/proc/wrist-env/lb"],
    "export under /proc": lambda t: ["export", "P1", "/proc/self/ex"],
}


@pytest.mark.parametrize("make_argv", OUT_THE_SYSTEM_REFUSES.values(), ids=OUT_THE_SYSTEM_REFUSES)
def test_an_out_path_the_system_refuses_is_one_line_naming_it(make_argv, capsys, tmp_path):
    argv = make_argv(tmp_path)
    assert main(argv) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and err.startswith("wrist-bench: error: ") and "Traceback" not in err
    assert ("/proc/" in err) if "/proc/" in " ".join(argv) else str(tmp_path / "a-file") in err


def _refuse(monkeypatch, owner, name):
    """Make `owner.name` (a long run) fail the test if a command reaches it before its checks."""

    def reached(*args, **kwargs):
        raise AssertionError(f"{name} ran before the command's checks")

    monkeypatch.setattr(owner, name, reached)


def _one_line_error(capsys, argv, status=2) -> str:
    assert main(argv) == status
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and err.startswith("wrist-bench: ") and "Traceback" not in err, err
    return err


OUTPUTS_CHECKED_FIRST = {
    "calibrate --out a folder": (lambda t: ["calibrate", "P1", "--out", str(t)], "a folder, not a file"),
    "calibrate --out under a file": (lambda t: ["calibrate", "P1", "--out", str(_file(t) / "x.json")], "is a file"),
    "calibrate --out under /proc": (lambda t: ["calibrate", "P1", "--out", "/proc/wrist/x.json"], "cannot write in"),
    "calibrate --out empty": (lambda t: ["calibrate", "P1", "--out", ""], "--out is empty"),
    "posterior --out a file": (lambda t: ["posterior", "P1", "--out", str(_file(t))], "a file, not a folder"),
    "posterior --report under /proc": (
        lambda t: ["posterior", "P1", "--out", str(t), "--report", "/proc/wrist/r"],
        "--report /proc/wrist/r: cannot write in",
    ),
}


@pytest.mark.parametrize("make_argv, message", OUTPUTS_CHECKED_FIRST.values(), ids=OUTPUTS_CHECKED_FIRST)
def test_an_output_is_checked_before_the_run_not_after(make_argv, message, capsys, tmp_path, monkeypatch):
    """calibrate --out and posterior --out were written after the whole run, which an unwritable path lost."""
    from wrist_env.cli.run import identification, studies

    _refuse(monkeypatch, studies.bench, "calibrate")
    _refuse(monkeypatch, identification, "study")
    argv = make_argv(tmp_path)
    err = _one_line_error(capsys, argv)
    assert message in err and ("--report" in err or "--out" in err), err


STORAGE_CHECKED_FIRST = {
    "unknown scheme": (["--optimizer", "optuna-tpe", "--storage", "foo://x"], "the Optuna storage 'foo://x' cannot"),
    "not a URL": (["--optimizer", "optuna-tpe", "--storage", "runs/x.db"], "the Optuna storage 'runs/x.db' cannot"),
    "unwritable SQLite": (
        ["--optimizer", "optuna-cmaes", "--storage", "sqlite:////proc/wrist/x.db"],
        "'sqlite:////proc/wrist/x.db' cannot be opened (OperationalError",
    ),
    "a calibrator without a study": (
        ["--optimizer", "cmaes", "--storage", "sqlite:///x.db"],
        "cmaes keeps no Optuna study; --storage is for optuna-cmaes, optuna-tpe",
    ),
}


@pytest.mark.parametrize("options, message", STORAGE_CHECKED_FIRST.values(), ids=STORAGE_CHECKED_FIRST)
def test_calibrate_checks_the_storage_url_before_the_run(options, message, capsys, monkeypatch):
    from wrist_env.cli.run import studies

    _refuse(monkeypatch, studies.bench, "calibrate")
    assert message in _one_line_error(capsys, ["calibrate", "P1", *options])


def test_calibrate_storage_memory_is_none(monkeypatch):
    from wrist_env.cli.run import studies

    seen = {}

    def fake(participant, name, budget, seed, *, log, storage, instance):
        seen["storage"] = storage
        raise KeyboardInterrupt  # stop here: the storage is what is tested

    monkeypatch.setattr(studies.bench, "calibrate", fake)
    assert main(["calibrate", "P1", "--optimizer", "optuna-tpe", "--storage", "memory"]) == 130
    assert seen == {"storage": None}


def test_calibrate_on_an_instance_is_seeded_with_it_unless_told(monkeypatch):
    from wrist_env.cli.run import studies

    seen = []

    def fake(participant, name, budget, seed, *, log, storage, instance):
        seen.append((seed, instance))
        raise KeyboardInterrupt  # stop here: the seed and the instance are what is tested

    monkeypatch.setattr(studies.bench, "calibrate", fake)
    for extra in (["--instance", "3"], ["--instance", "3", "--seed", "7"], []):
        assert main(["calibrate", "P1", *extra]) == 130
    assert seen == [(3, 3), (7, 3), (0, 0)]


def _one_calibrator_benchmark(tmp_path) -> list[str]:
    """`benchmark` of P1 with the random calibrator into tmp_path, without a progress bar (the instance tests')."""
    return [
        "benchmark",
        "--participants",
        "P1",
        "--optimizers",
        "random",
        "--out",
        str(tmp_path / "b"),
        "--no-progress",
    ]


@pytest.mark.parametrize(
    "extra, seeds, instances",
    [
        ([], "instance", [0, 1, 2, 3, 4]),  # the default: instances 0 .. 4, each seeded with its number
        (["--seeds", "2"], 2, None),  # the benchmark before instances: seeds 0, 1 on instance 0
        (["--instances", "3"], "instance", 3),  # instances 1 .. 3, each seeded with its number
        (["--instances", "3", "--seeds", "2"], 2, 3),
        (["--instances", "2-4"], "instance", [2, 3, 4]),
        (["--instances", "0,7"], "instance", [0, 7]),
    ],
)
def test_benchmark_instances_and_seeds(extra, seeds, instances, monkeypatch, tmp_path, capsys):
    from wrist_env.cli.run import studies

    seen = {}

    def fake(participants, names, seeds, budget, out, *, instances, **kwargs):
        seen.update(seeds=seeds, instances=instances)
        raise KeyboardInterrupt

    monkeypatch.setattr(studies.bench, "benchmark", fake)
    argv = _one_calibrator_benchmark(tmp_path)
    assert main(argv + extra) == 130
    assert seen == {"seeds": seeds, "instances": instances}
    n_instances = 1 if instances is None else instances if isinstance(instances, int) else len(instances)
    n_seeds = 1 if seeds == "instance" else seeds
    assert capsys.readouterr().out.startswith(f"{n_instances * n_seeds} cells: participants P1")


def test_benchmark_defaults_to_seeds_on_instance_0_with_a_participant_not_built_in():
    from wrist_env.cli.run.studies import DEFAULT_SEEDS, benchmark_seeds

    assert benchmark_seeds(None, None, ["P1", "U1"]) == (DEFAULT_SEEDS, None)  # U1's task has no instances
    assert benchmark_seeds(None, None, ["P1", "P3"]) == ("instance", [0, 1, 2, 3, 4])
    assert benchmark_seeds(3, None, ["U1"]) == (3, None)


def test_benchmark_names_a_range_of_instances_as_one(monkeypatch, tmp_path, capsys):
    from wrist_env.cli.run import studies

    monkeypatch.setattr(studies.bench, "benchmark", lambda *a, **k: (_ for _ in ()).throw(KeyboardInterrupt))
    argv = _one_calibrator_benchmark(tmp_path)
    assert main([*argv, "--instances", "500"]) == 130
    assert capsys.readouterr().out.startswith(
        "500 cells: participants P1 (instances 1-500) x calibrators random x seed"
    )


def test_ctrl_c_in_calibrate_says_what_was_saved(capsys, tmp_path, monkeypatch):
    from wrist_env.cli.run import studies

    def interrupted(*args, **kwargs):
        raise KeyboardInterrupt

    monkeypatch.setattr(studies.bench, "calibrate", interrupted)
    err = _one_line_error(capsys, ["calibrate", "P1"], status=130)
    assert "calibration interrupted; nothing was saved (with --log <folder> a run can be resumed)" in err
    log = tmp_path / "log"
    err = _one_line_error(capsys, ["calibrate", "P1", "--log", str(log)], status=130)
    assert f"the evaluations logged in {log} are kept: rerun the same command to resume" in err


def test_ctrl_c_in_a_benchmark_says_what_was_saved_and_how_to_resume(capsys, tmp_path, monkeypatch):
    from wrist_env.cli.run import studies

    def interrupted(*args, **kwargs):
        raise KeyboardInterrupt

    monkeypatch.setattr(studies.bench, "benchmark", interrupted)
    out = tmp_path / "bench"
    argv = ["benchmark", "--participants", "P1", "--optimizers", "random", "--out", str(out), "--no-progress"]
    err = _one_line_error(capsys, argv, status=130)
    assert f"benchmark interrupted; 0 evaluations logged in {out} are kept" in err
    assert "rerun the same command to resume" in err


def test_a_leaderboard_of_a_log_with_no_finished_cell_is_one_line(capsys, tmp_path):
    runs = tmp_path / "runs"
    (runs / "evals").mkdir(parents=True)
    err = _one_line_error(capsys, ["leaderboard", "--runs", str(runs), "--out", str(tmp_path / "lb")])
    assert f"{runs}: holds no finished benchmark cell" in err and f"benchmark --out {runs}" in err
    assert not (tmp_path / "lb").exists()


def test_export_refuses_an_empty_name_or_folder(capsys, tmp_path):
    err = _one_line_error(capsys, ["export", "P1", str(tmp_path / "w"), "--name", ""])
    assert "--name is empty" in err and not (tmp_path / "w").exists()
    assert "export's folder is empty" in _one_line_error(capsys, ["export", "P1", ""])


def test_posterior_model_trials_of_a_folder_participant_is_refused_saying_why(capsys, tmp_path, monkeypatch):
    """A folder participant has no hidden truth to simulate: it was a traceback after building its model."""
    from wrist_env.cli.run import identification
    from wrist_env.participants import registry

    _refuse(monkeypatch, identification, "study")
    registry._FOLDERS["U1"] = tmp_path  # registered (the autouse fixture forgets it)
    err = _one_line_error(capsys, ["posterior", "U1", "--model-trials", "--out", str(tmp_path / "p")])
    assert "--model-trials simulates a participant's hidden truth, which U1 (read from a folder)" in err


def test_every_number_a_user_types_is_bounded():
    """Walk every command's parser: no option takes a bare int or float (each takes `limits.bounded_int`
    or `bounded_float`, the limit in its message)."""
    from wrist_env.cli import parser

    sub = next(a for a in parser()._actions if a.dest == "command")
    bare = [
        f"{name} {'/'.join(action.option_strings) or action.dest}"
        for name, command in sub.choices.items()
        for action in command._actions
        if action.type in (int, float)
    ]
    assert not bare, bare
    numbers = [
        a for c in sub.choices.values() for a in c._actions if getattr(a.type, "__name__", "") in ("integer", "number")
    ]
    assert len(numbers) >= 25
