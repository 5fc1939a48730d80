"""`wrist-bench validate`: the measures on known geometry, strict JSON, the CLI, and (xfail) the bands."""

import json
import math

import numpy as np
import pytest

from wrist_env import design, ligaments, validation
from wrist_env.cli import main
from wrist_env.model import CAPITATE
from wrist_env.validation.chain import _row

pytestmark = pytest.mark.slow  # builds models or runs simulations/studies (minutes)

CHECK_IDS = (
    "scaphoid_slope",
    "lunate_slope",
    "scaphoid_above_lunate",
    "rs_rl_force_ratio",
    "midcarpal_stt_share_pct",
    "midcarpal_sc_share_pct",
    "midcarpal_lc_share_pct",
    "midcarpal_th_share_pct",
    "ulnar_share_pct",
    "column_rotation_deg",
    "hamate_rotation_deg",
    "sl_gap_growth_mm",
    "rs_mean_pressure_mpa",
    "slil_force_30ext_n",
)


def test_slope_recovers_a_known_line_and_ignores_nan():
    x = np.linspace(40, -40, 17)
    y = 0.72 * x + 3.0 + 0.01 * np.sin(np.arange(17))
    assert validation.slope(x, y) == pytest.approx(0.72, abs=2e-3)
    y[4] = np.nan
    assert validation.slope(x, y) == pytest.approx(0.72, abs=2e-3)
    assert math.isnan(validation.slope(np.ones(5), np.arange(5.0)))


def _pose(translation=(0, 0, 0), angle_deg=0.0):
    from scipy.spatial.transform import Rotation

    T = np.eye(4)
    T[:3, :3] = Rotation.from_euler("z", angle_deg, degrees=True).as_matrix()
    T[:3, 3] = translation
    return T


def test_surface_gap_of_two_translated_boxes():
    import trimesh

    box = trimesh.creation.box(extents=(10.0, 10.0, 10.0))
    mesh = (np.asarray(box.vertices), np.asarray(box.faces))
    moved = (np.asarray(box.vertices) + [13.0, 0.0, 0.0], np.asarray(box.faces))
    # the copy 13 mm along x: faces 3 mm apart; then both posed: the second moved 2 mm further, the first turned
    a_poses = np.stack([_pose(), _pose(), _pose(angle_deg=90.0)])
    b_poses = np.stack([_pose(), _pose((2.0, 0.0, 0.0)), _pose()])
    gap = validation.surface_gap_mm(mesh, moved, a_poses, b_poses)
    np.testing.assert_allclose(gap, [3.0, 5.0, 3.0], atol=1e-9)
    a_poses[1, 0, 0] = np.nan
    assert math.isnan(validation.surface_gap_mm(mesh, moved, a_poses, b_poses)[1])


def test_with_tears_uses_the_injurable_names():
    d = validation.with_tears(design.population(), validation.SLIL)
    torn = {n for n, t in zip(ligaments.LIGAMENT_NAMES, d.torn) if t}
    assert torn == {"SLIL_v", "SLIL_p", "SLIL_d"}
    assert not design.population().torn.any()


def test_report_json_is_strict_and_round_trips():
    inf, nan = float("inf"), float("nan")
    rows = (
        validation.Check("a", "finite", 1.5, (1.0, 2.0), "mm", "src", True),
        validation.Check("b", "failed run", nan, (3.0, inf), "mm", "src", False),
    )
    series = {
        "capitate_angle_deg": np.array([40.0, 0.0, -40.0]),
        "sl_gap_intact_mm": np.array([1.0, nan, 1.2]),
        "intact_status": "ok",
    }
    report = validation.Report("X", rows, series, 1.25)
    text = json.dumps(report.to_dict(), allow_nan=False)
    back = json.loads(text)
    assert back["passed"] is False
    assert back["checks"][0] == {
        "id": "a",
        "description": "finite",
        "value": 1.5,
        "band": [1.0, 2.0],
        "unit": "mm",
        "source": "src",
        "passed": True,
    }
    assert back["checks"][1]["value"] is None and back["checks"][1]["band"] == [3.0, None]
    assert back["series"]["sl_gap_intact_mm"] == [1.0, None, 1.2] and back["series"]["intact_status"] == "ok"
    assert "FAIL" in validation.format_table(report)


def test_cli_validate_json_has_the_fourteen_checks(capsys, built, tmp_path):
    built("P1")
    code = main(["validate", "P1", "--json", "--out", str(tmp_path)])
    out = json.loads(capsys.readouterr().out)
    assert tuple(c["id"] for c in out["checks"]) == CHECK_IDS == tuple(c.id for c in validation.CHECKS)
    for c in out["checks"]:
        assert len(c["band"]) == 2 and c["band"][0] is not None, c
        assert c["source"] and c["unit"] and isinstance(c["passed"], bool), c
        if c["value"] is not None:
            low, high = c["band"]
            assert c["passed"] == (low <= c["value"] <= (math.inf if high is None else high)), c
    assert code == (0 if all(c["passed"] for c in out["checks"]) else 1)
    ulnar = next(c for c in out["checks"] if c["id"] == "ulnar_share_pct")
    assert ulnar["description"].endswith("ulnar variance +0.26 mm"), ulnar  # the built-ins' seat (Yoshioka 2007)
    for c in out["checks"]:  # the neutral checks under their experiments' load mode (issue 54)
        neutral = c["id"] in ("rs_rl_force_ratio", "ulnar_share_pct") or c["id"].startswith("midcarpal_")
        assert ("the hand loaded axially, as in a jig" in c["description"]) == neutral, c
    assert out["participant"] == "P1" and len(out["series"]["capitate_angle_deg"]) == 17
    figure = tmp_path / "validation_P1.png"
    assert out["figure"] == str(figure) and figure.stat().st_size > 10_000


def test_a_failed_run_fails_its_check_and_says_why():
    row = _row(
        "sl_gap_growth_mm", "SL gap growth", 5.0, (3.0, math.inf), "mm", "SLIL-torn sweep run failed: NaN in the state"
    )
    assert math.isnan(row.value) and not row.passed and "failed: NaN in the state" in row.description


@pytest.mark.xfail(
    reason="issue 54: under the jig the load path misses RS/RL and the STT, LC and TH shares; the column's turn; docs/validation.md: The load path",
    strict=True,
    raises=AssertionError,
)
@pytest.mark.parametrize("name", ["P1", "P2", "P3"])
def test_builtins_pass_published_checks(name, built):
    report = validation.validate(name, model=built(name))
    failed = [(r.id, r.value, r.band) for r in report.rows if not r.passed]
    assert not failed, failed


@pytest.mark.parametrize("name", ["P1", "P2", "P3"])
def test_builtins_move_like_a_wrist(name, built):
    """The default anatomy (distal row, swept fossae, TC/TH): the scaphoid and lunate turn with the
    capitate within Rainbow 2013's bands, the scaphoid more, at cadaveric radioscaphoid pressures.
    Still failing, held by the strict xfail above: the radiocarpal load share (RS/RL under 1.1 under the
    tendon lines), the midcarpal shares and the column's turn (issue 54)."""
    report = validation.validate(name, model=built(name))
    for check in ("scaphoid_slope", "lunate_slope", "scaphoid_above_lunate", "rs_mean_pressure_mpa"):
        assert report.row(check).passed, report.row(check)
    assert report.row("rs_rl_force_ratio").value < 1.1  # an open item of issue 54: update when it passes
    shares = [report.row(f"midcarpal_{k}_share_pct").value for k in validation.VIEGAS_1993]
    assert sum(shares) == pytest.approx(100.0)
    # issue 54's open items under the tendon lines: the radial column carries less of the midcarpal load
    # than Viegas 1993's 23 %; the TFCC takes a share within the band (Palmer 1984: 18.4 %; band 10-25 %)
    assert shares[0] < 23.0 and report.row("ulnar_share_pct").passed, report.row("ulnar_share_pct")


def test_load_directions_are_the_clis_choices_and_unit_vectors():
    """`validate --load-direction` offers exactly `settings.LOAD_DIRECTIONS`; each is a set of lines of
    unit pulls whose shares sum to 1 and whose resultant pulls proximally, the axial one a single line
    along the radius' axis on the capitate, and another name is refused by name."""
    from wrist_env.cli import parser
    from wrist_env.participants.registry import load_model
    from wrist_env.solver import drivers
    from wrist_env.solver.settings import DEFAULT_LOADS, LOAD_DIRECTIONS

    validate = parser()._subparsers._group_actions[0].choices["validate"]
    option = next(a for a in validate._actions if "--load-direction" in a.option_strings)
    assert tuple(option.choices) == LOAD_DIRECTIONS and option.default == DEFAULT_LOADS
    p1 = load_model("P1")
    for name in LOAD_DIRECTIONS:
        lines = drivers.loads(p1, name)
        assert np.allclose(np.linalg.norm(lines.direction, axis=1), 1.0) and np.isclose(lines.share.sum(), 1.0)
        total = lines.share @ lines.direction
        assert total[1] > 0.9 * np.linalg.norm(total), (name, total)
    axial = drivers.loads(p1, "axial")
    assert np.array_equal(axial.direction, [[0.0, 1.0, 0.0]]) and axial.body.tolist() == [CAPITATE]
    with pytest.raises(ValueError, match="sideways"):
        drivers.loads(p1, "sideways")


def test_the_default_solver_validates_like_the_diagonal_mass(built):
    """Issue 32's bar, met when issue 52 made the block mass the default: P1's slopes and ratios are within
    0.01 of the diagonal mass's (`SolverSettings.diagonal()`; measured < 0.0005 on P1–P3, the load shares
    to 0.003 points)."""
    from wrist_env.solver.settings import solver_settings

    model = built("P1")
    reports = [validation.validate("P1", model=model, settings=solver_settings(s)) for s in ("diagonal", "default")]
    for check in ("scaphoid_slope", "lunate_slope", "scaphoid_above_lunate", "rs_rl_force_ratio"):
        a, b = (r.row(check).value for r in reports)
        assert abs(a - b) < 0.01, (check, a, b)
    for k in validation.VIEGAS_1993:
        a, b = (r.row(f"midcarpal_{k}_share_pct").value for r in reports)
        assert abs(a - b) < 0.1, (k, a, b)
    with pytest.raises(ValueError, match="solver must be one of"):
        solver_settings("implicit")
