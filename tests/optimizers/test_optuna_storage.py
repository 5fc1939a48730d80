"""One owner of Optuna storages (`optimizers.optuna_storage.open_storage`): the benchmark's URLs and a user's
storage option are opened the same way."""

import pytest

import optimizers
from optimizers.optuna_storage import open_storage
from wrist_env.errors import InputError


def test_a_sqlite_url_gets_wal_journaling_whoever_opens_it(tmp_path):
    storage = open_storage(f"sqlite:///{tmp_path / 'a.db'}")
    with storage.engine.connect() as connection:
        assert connection.exec_driver_sql("PRAGMA journal_mode").scalar() == "wal"


def test_memory_a_storage_object_and_a_journal_path(tmp_path):
    assert open_storage(None) is None
    journal = open_storage(tmp_path / "journal.log")
    assert type(journal).__name__ == "JournalStorage" and open_storage(journal) is journal


def test_a_calibrator_given_a_url_that_cannot_open_names_it(tmp_path):
    bad = f"sqlite:///{tmp_path / 'missing' / 'x.db'}"
    with pytest.raises(InputError, match="the Optuna storage 'sqlite:///.*missing/x.db' cannot be opened"):
        optimizers.get("optuna-tpe")(22, 8, 0, storage=bad)
