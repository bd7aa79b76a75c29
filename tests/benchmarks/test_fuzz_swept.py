"""``benchmarks.fuzz_swept``: chunks written as they finish, a rerun resumes, the merge adds up."""

from __future__ import annotations

import json

import pytest

from benchmarks import fuzz_swept


@pytest.mark.slow
def test_runs_in_chunks_and_resumes(tmp_path, monkeypatch):
    chunks, out = tmp_path / "chunks", tmp_path / "out"
    argv = ["--n", "3", "--seed", "203869", "--chunk", "2", "--chunks", str(chunks)]
    fuzz_swept.main([*argv, "--out", str(out)])
    assert sorted(p.name for p in chunks.iterdir()) == ["chunk_203869.json", "chunk_203871.json"]
    data = json.loads((out / "fuzz_swept.json").read_text())
    parts = [json.loads(p.read_text()) for p in sorted(chunks.iterdir())]
    assert data["scenes"] == 3 == sum(p["scenes"] for p in parts)
    assert data["valid"] == sum(p["valid"] for p in parts) >= 2
    assert data["seeds"] == [203869, 203871]
    assert data["violations"] == {}  # seed 203869 is a fixed finding of the longer run
    assert "python -m benchmarks.fuzz_swept --n 3" in (out / "fuzz_swept.md").read_text()

    # a rerun finds every chunk and fuzzes nothing
    def boom(*a, **k):
        raise AssertionError("a finished chunk was fuzzed again")

    monkeypatch.setattr(fuzz_swept, "run_many", boom)
    fuzz_swept.main([*argv, "--out", str(out)])
    again = json.loads((out / "fuzz_swept.json").read_text())
    assert {k: again[k] for k in ("scenes", "valid", "violations")} == {
        k: data[k] for k in ("scenes", "valid", "violations")
    }


def test_merge_counts_violations_and_failing_seeds(tmp_path):
    for seed, kinds in ((10, {"frame": 1}), (5, {"frame": 2, "crash": 1})):
        (tmp_path / f"chunk_{seed}.json").write_text(
            json.dumps(
                {
                    "scenes": 5, "valid": 4, "violations": kinds, "seconds": 2.5,
                    "slowest_query_s": {"partial in": float(seed)},
                    "failing_scenes": [{"seed": seed, "features": [], "findings": []}],
                }
            )
        )  # fmt: skip
    m = fuzz_swept.merge(sorted(tmp_path.iterdir()))
    assert m["violations"] == {"frame": 3, "crash": 1}
    assert (m["scenes"], m["valid"], m["seconds"]) == (10, 8, 5.0)
    assert [f["seed"] for f in m["failing_scenes"]] == [5, 10]
    assert m["slowest_query_s"] == {"partial in": 10.0}
    assert "Failing seeds: 5, 10." in fuzz_swept.render(
        {**m, "seeds": [5, 14], "chunk": 5, "command": "python -m benchmarks.fuzz_swept"}
    )


def test_bad_arguments_fail_clearly():
    with pytest.raises(SystemExit):
        fuzz_swept.main(["--chunk", "0"])


def test_certify_variant_writes_its_own_result(tmp_path):
    from benchmarks import fuzz_certify

    chunks, out = tmp_path / "chunks", tmp_path / "out"
    fuzz_certify.main(["--n", "1", "--seed", "300001", "--chunks", str(chunks), "--out", str(out)])
    data = json.loads((out / "fuzz_certify.json").read_text())
    part = json.loads((chunks / "chunk_300001.json").read_text())
    assert "swept bounds" in part["slowest_query_s"]  # the certified bounds ran
    assert data["violations"] == {} and data["valid"] == 1
    assert "python -m benchmarks.fuzz_certify --n 1" in (out / "fuzz_certify.md").read_text()
