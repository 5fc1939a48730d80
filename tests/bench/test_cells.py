"""The benchmark's cells: participants × instances × calibrators × seeds, seed = instance by default with instances."""

import pytest

from wrist_env.bench import SEED_IS_INSTANCE, RunKey, make_cells
from wrist_env.errors import InputError


def test_without_instances_the_cells_are_those_before_instances():
    cells = make_cells(["P1", "P2"], ["random"], 2, 8)
    assert cells == [RunKey(p, "random", s, 8) for p in ("P1", "P2") for s in (0, 1)]
    assert {k.instance for k in cells} == {0}


def test_instances_seeded_by_their_number_as_coco():
    cells = make_cells(["P1", "P2"], ["random", "cmaes"], SEED_IS_INSTANCE, 300, instances=3)
    assert len(cells) == 2 * 3 * 2
    assert all(k.seed == k.instance for k in cells)
    assert [(k.participant, k.instance, k.optimizer) for k in cells[:4]] == [
        ("P1", 1, "random"),
        ("P1", 1, "cmaes"),
        ("P1", 2, "random"),
        ("P1", 2, "cmaes"),
    ]
    assert cells[0].name == "P1.i1.random.seed1.budget300"


def test_explicit_seeds_cross_every_instance():
    cells = make_cells(["P1"], ["random"], [7, 9], 8, instances=[0, 4])
    assert [(k.instance, k.seed) for k in cells] == [(0, 7), (0, 9), (4, 7), (4, 9)]
    assert [k.seed for k in make_cells(["P1"], ["random"], 2, 8, instances=2)] == [0, 1, 0, 1]


@pytest.mark.parametrize(
    "instances, message",
    [
        (0, r"instances must be an integer in \[1, 10,000\], but got 0"),
        ([1, 1], r"instances must not repeat, but got \[1, 1\]"),
        ([-1], r"instance must be an integer in \[0, 10,000\], but got -1"),
        ([], "at least one instance"),
    ],
)
def test_bad_instances_are_refused_naming_them(instances, message):
    with pytest.raises(InputError, match=message):
        make_cells(["P1"], ["random"], 1, 8, instances=instances)


def test_seeds_other_than_a_count_a_list_or_instance_are_refused():
    with pytest.raises(InputError, match=r"seeds must be a count, a list of seeds or 'instance', but got 'inst'"):
        make_cells(["P1"], ["random"], "inst", 8, instances=2)


def test_a_folder_participant_has_no_drawn_instances(tmp_path, monkeypatch):
    from wrist_env.bench import benchmark
    from wrist_env.errors import ParticipantError
    from wrist_env.participants import registry

    monkeypatch.setattr(registry, "require", lambda *names: None)  # as if U1 were a registered folder
    with pytest.raises(ParticipantError, match=r"instances k >= 1 .* but U1 is not one: run it on instance 0"):
        benchmark(["U1"], ["random"], 1, 8, tmp_path / "runs", instances=[0, 2], progress=False)
    assert not (tmp_path / "runs" / "evals").exists()  # refused before anything ran


def test_instances_times_seeds_is_bounded_before_the_cells_are_made():
    with pytest.raises(InputError, match=r"instances x seeds\) must be at most 10,000, but got 10,000 x 2"):
        make_cells(["P1"], ["random"], 2, 8, instances=10_000)
    assert len(make_cells(["P1"], ["random"], SEED_IS_INSTANCE, 8, instances=10_000)) == 10_000
