"""read_study refuses a study file whose schema was altered by hand
(docs/store.md, "Opening"): each alteration of
tests/data/store_schema/alterations.txt, made with Python's own sqlite3 on a
file holding the current schema (tests/data/store_schema/study_vN.sql), raises
StudyFileError naming the file and the difference, and the file's SHA-256 is
unchanged. The unaltered file is read (it holds no trials)."""
import hashlib
import sqlite3

import pytest

from conftest import SOURCE, atonlab

pytest.importorskip("pandas", reason="missing tool: python3-pandas")

FIXTURES = SOURCE / "tests" / "data" / "store_schema"
APPLICATION_ID = 0x41544F4E  # 'ATON' (store/include/atonlab/store/schema.h)


def current_version():
    return max(int(p.stem.removeprefix("study_v")) for p in FIXTURES.glob("study_v*.sql"))


def make_study(path):
    version = current_version()
    with sqlite3.connect(path) as db:
        db.executescript((FIXTURES / f"study_v{version}.sql").read_text())
        db.execute(f"PRAGMA user_version = {version}")
        db.execute(f"PRAGMA application_id = {APPLICATION_ID}")
    db.close()


def alterations():
    out = []
    for line in (FIXTURES / "alterations.txt").read_text().splitlines():
        if line and not line.startswith("#"):
            name, says, sql = line.split("|", 2)
            out.append(pytest.param(says, sql, id=name))
    return out


def sha256(path):
    return hashlib.sha256(path.read_bytes()).hexdigest()


def test_an_unaltered_study_is_read(tmp_path):
    db = tmp_path / "study.db"
    make_study(db)
    assert len(atonlab.read_study(db)) == 0


@pytest.mark.parametrize("says,sql", alterations())
def test_an_altered_study_is_refused_and_unchanged(tmp_path, says, sql):
    db = tmp_path / "study.db"
    make_study(db)
    with sqlite3.connect(db) as raw:
        raw.executescript(sql)
    raw.close()
    before = sha256(db)
    with pytest.raises(atonlab.StudyFileError) as e:
        atonlab.read_study(db)
    assert f"{db}'s schema was altered ({says}" in str(e.value)
    assert "it was not changed" in str(e.value)
    assert e.value.file == str(db)
    assert sha256(db) == before
