"""The executor both studies use: this process, local processes (dying with their parent), errors handed back."""

import subprocess
import sys
import textwrap

import pytest

from wrist_env.runs.executor import Inline, Processes, executor


def _square(x):
    if x < 0:
        raise ValueError(f"negative {x}")
    return x * x


@pytest.mark.parametrize("make", [lambda: Inline(), lambda: Processes(2, threads=1)], ids=["inline", "processes"])
def test_results_hand_back_values_and_errors(make):
    with make() as ex:
        handles = {ex.submit(_square, x): x for x in (1, -2, 3)}
        out = {handles[h]: (value, error) for h, value, error in ex.results(list(handles))}
    assert out[1] == (1, None) and out[3] == (9, None)
    assert out[-2][0] is None and isinstance(out[-2][1], ValueError)


def test_executor_chooses_by_workers():
    assert isinstance(executor(None, 0), Inline) and isinstance(executor(None, 1), Inline)
    with executor(None, 2, threads=1) as ex:
        assert isinstance(ex, Processes) and (ex.workers, ex.threads) == (2, 1)


def test_local_workers_die_with_their_parent(tmp_path, kill_parent):
    psutil = pytest.importorskip("psutil")
    script = textwrap.dedent("""
        import sys, time
        from wrist_env.runs.executor import Processes
        if __name__ == "__main__":
            ex = Processes(2, threads=1)
            handles = [ex.submit(time.sleep, 600) for _ in range(2)]
            time.sleep(3)
            print("ready", flush=True)
            time.sleep(600)
    """)
    path = tmp_path / "parent.py"
    path.write_text(script)
    proc = subprocess.Popen([sys.executable, str(path)], stdout=subprocess.PIPE, text=True)
    try:
        assert proc.stdout.readline().strip() == "ready"
        workers = [
            c for c in psutil.Process(proc.pid).children(recursive=True) if "spawn_main" in " ".join(c.cmdline())
        ]
        assert len(workers) == 2
        kill_parent(proc, workers)
    finally:
        if proc.poll() is None:
            proc.kill()


def test_an_unreachable_scheduler_is_one_line_naming_it(monkeypatch, tmp_path, capsys):
    import importlib

    from wrist_env.cli import main

    monkeypatch.setattr(importlib.import_module("wrist_env.runs.executor"), "CONNECT_TIMEOUT_S", 1.0)
    argv = ["montecarlo", "P1", "--n", "2", "--scheduler", "tcp://127.0.0.1:1", "--out", str(tmp_path), "--no-progress"]
    assert main(argv) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "cannot reach the dask scheduler 'tcp://127.0.0.1:1' within 1 s" in err


def _cluster(workers: int):
    """An in-process dask cluster (no processes, no dashboard) with `workers` workers."""
    distributed = pytest.importorskip("distributed")
    return distributed.LocalCluster(n_workers=workers, processes=False, dashboard_address=None, threads_per_worker=1)


def test_a_scheduler_with_no_workers_is_named_with_how_to_add_one(monkeypatch):
    """Tasks on a scheduler without a worker would wait forever: after the timeout, one error says why."""
    import importlib

    from wrist_env.runs.executor import SchedulerError

    monkeypatch.setattr(importlib.import_module("wrist_env.runs.executor"), "NO_WORKERS_TIMEOUT_S", 0.5)
    with _cluster(0) as cluster, executor(cluster.scheduler_address) as ex:
        handles = [ex.submit(_square, 2)]
        with pytest.raises(SchedulerError) as err:
            list(ex.results(handles, poll_seconds=0.05))
    message = str(err.value)
    assert "has had no workers" in message and f"dask worker {cluster.scheduler_address}" in message
    assert "\n" not in message


def test_a_cancelled_task_is_the_schedulers_error_not_the_tasks():
    """A scheduler stopped mid-run cancels the tasks (FutureCancelledError): that is no task's failure."""
    from wrist_env.runs.executor import SchedulerError

    with _cluster(0) as cluster, executor(cluster.scheduler_address) as ex:  # no worker: the task waits
        handle = ex.submit(_square, 2)
        ex.client.cancel([handle])
        with pytest.raises(SchedulerError, match=f"scheduler {cluster.scheduler_address} cancelled a task"):
            list(ex.results([handle], poll_seconds=0.05))


@pytest.mark.parametrize(
    "address, match",
    [
        ("tls://127.0.0.1:1", "is TLS, but dask has no client certificate configured"),
        ("http://127.0.0.1:1", "scheme 'http', which this client cannot use"),
        ("ucx://127.0.0.1:1", "scheme 'ucx', which this client cannot use"),
        ("", "address is empty"),
    ],
)
def test_a_scheduler_address_this_client_cannot_use_is_one_line(address, match, tmp_path, capsys):
    from wrist_env.cli import main

    argv = ["montecarlo", "P1", "--n", "2", "--scheduler", address, "--out", str(tmp_path), "--no-progress"]
    assert main(argv) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and match in err, err
