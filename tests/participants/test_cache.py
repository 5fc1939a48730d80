"""The model cache refused before a build it could not keep, and a build kept when the cache fails after it."""

import re

import pytest

from wrist_env.errors import StoreError
from wrist_env.participants import builtin, registry


@pytest.fixture
def must_build(monkeypatch):
    """P1 with no shipped model to read: load_model would build (the stand-in build fails the test)."""
    monkeypatch.setattr(builtin, "shipped_source_hash", lambda name: None)
    monkeypatch.setattr(
        "wrist_env.builder.pipeline.build_model", lambda *a, **k: pytest.fail("built before the cache was checked")
    )


def test_a_cache_that_is_a_file_is_named_before_the_build(must_build, monkeypatch, tmp_path):
    (tmp_path / "cache").write_text("")
    monkeypatch.setenv("WRIST_ENV_CACHE", str(tmp_path / "cache"))
    with pytest.raises(StoreError, match=re.escape(str(tmp_path / "cache")) + ".*cannot be written.*WRIST_ENV_CACHE"):
        registry.load_model("P1")


def test_a_cached_json_that_is_a_folder_is_named_before_the_build(must_build, monkeypatch, tmp_path):
    monkeypatch.setenv("WRIST_ENV_CACHE", str(tmp_path))
    digest = registry.source_hash("P1", registry.bones("P1"), registry.build_params("P1"))
    (tmp_path / f"P1-{digest}.json").mkdir()
    with pytest.warns(UserWarning, match="rebuilding"), pytest.raises(StoreError, match=r"\.json: a folder where"):
        registry.load_model("P1")


def test_a_model_built_but_not_cached_is_still_returned(monkeypatch, tmp_path):
    class Built:
        def save(self, path):
            raise PermissionError(13, "Permission denied", str(path))

    monkeypatch.setattr(builtin, "shipped_source_hash", lambda name: None)
    monkeypatch.setattr("wrist_env.builder.pipeline.build_model", lambda *a, **k: Built())
    monkeypatch.setenv("WRIST_ENV_CACHE", str(tmp_path))
    with pytest.warns(UserWarning, match="could not be cached.*Permission denied"):
        assert isinstance(registry.load_model("P1"), Built)


def test_a_cache_error_is_one_line_on_the_command_line(must_build, monkeypatch, tmp_path, capsys):
    from wrist_env.cli import main

    (tmp_path / "cache").write_text("")
    monkeypatch.setenv("WRIST_ENV_CACHE", str(tmp_path / "cache"))
    assert main(["build", "P1"]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "model cache cannot be written" in err
