"""femdyn study's outputs as a Python user reads them: study.csv by pandas with comment='#'
(the comment lines carry the sampling, the error's scales, the reference and the machine with
its load), and the --json report on stdout, the same runs and numbers."""
import json
import subprocess

import pandas
import pytest

from conftest import BINARY, model_path


def test_study_csv_reads_with_pandas_and_matches_the_json_report(tmp_path):
    out = subprocess.run([str(BINARY), "study", model_path("models/pendulum.json"), "--quick",
                          "--json", "--out", str(tmp_path)], capture_output=True, text=True,
                         timeout=600)
    if out.returncode == 2 and "refusing to time a Debug build" in out.stderr:
        pytest.skip("study refuses to time a build with asserts")
    if out.returncode == 2 and "built without Simbody" in out.stderr:
        pytest.skip("femdyn built without Simbody: no study command")
    assert out.returncode == 0, out.stderr[-3000:]
    report = json.loads(out.stdout)

    text = (tmp_path / "study.csv").read_text(encoding="utf-8")
    comments = [line for line in text.splitlines() if line.startswith("#")]
    assert any(line.startswith("# machine: ") and " cores; load average (1, 5, 15 min) " in line
               for line in comments)
    assert any(line.startswith("# error: relative state error") for line in comments)
    assert any(line.startswith("# sampling: both engines step freely") for line in comments)

    table = pandas.read_csv(tmp_path / "study.csv", comment="#")
    assert len(table) == len(report["runs"]) > 20
    for column in ("engine", "integrator", "setting", "value", "error", "position_error",
                   "rate_error", "wall_time", "repeats", "warm_up_time", "wall_time_min",
                   "wall_time_max", "steps", "ok", "resolved"):
        assert column in table.columns
    assert set(table["engine"]) == {"femdyn", "Simbody"}
    runs = pandas.DataFrame(report["runs"])
    assert list(table["integrator"]) == list(runs["integrator"])
    assert (abs(table["error"] - runs["error"]) <= 1e-9 * runs["error"].abs()).all()
    assert (abs(table["wall_time"] - runs["wall_time"]) <= 1e-9 * runs["wall_time"]).all()
    ok = table[table["ok"] == 1]
    # three timed runs after a warm-up, the median between the smallest and the largest
    assert (ok["repeats"] == 3).all()
    assert ((ok["wall_time_min"] <= ok["wall_time"]) & (ok["wall_time"] <= ok["wall_time_max"])).all()
    assert len(report["machine"]["load_start"]) == 3 and report["machine"]["cores"] >= 1
