import json

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
    for key in ("build_seconds", "morph_error_mm", "fibres", "cartilage_thickness_mm", "joint_space_mm", "contact_law_r2"):
        assert key in summary, key
    assert summary["fibres"]["SLIL_d"] == 7 and summary["fibres"]["UL"] == 3
    assert set(summary["cartilage_thickness_mm"]["radioscaphoid"]) == {"min", "mean", "max"}
    assert summary["build_seconds"] > 0


def test_unknown_participant_is_a_clear_error(capsys):
    assert main(["build", "P9"]) == 2
    assert "unknown participant 'P9'" in capsys.readouterr().err
