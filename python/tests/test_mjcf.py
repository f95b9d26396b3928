"""One truth across formats: an MJCF model loaded by Python equals the femdyn JSON that
`femdyn import` writes of it, and the CLI's equations, at the same state."""
import subprocess

import numpy as np

import femdyn
from conftest import BINARY, ROOT, cli_json, numbers

FEATURES = ROOT / "tests" / "data" / "mjcf" / "features.xml"


def test_mjcf_equals_its_import_and_the_cli(tmp_path):
    json_path = tmp_path / "features.json"
    subprocess.run([str(BINARY), "import", str(FEATURES), "-o", str(json_path)], check=True,
                   capture_output=True)
    direct, imported = femdyn.load(str(FEATURES)), femdyn.load(str(json_path))
    assert direct.coordinates == imported.coordinates
    rng = np.random.default_rng(4)
    q = direct.neutral_configuration()
    hinges = [i for i, name in enumerate(direct.configuration) if ".q" not in name]
    q[hinges] += rng.uniform(-0.5, 0.5, len(hinges))
    v = rng.uniform(-1, 1, direct.n)
    a, b = direct.equations(q, v), imported.equations(q, v)
    assert np.max(np.abs(a.M - b.M)) <= 1e-14 * np.max(np.abs(a.M))
    assert np.max(np.abs(a.h - b.h)) <= 1e-13 * max(1.0, np.max(np.abs(a.h)))
    cli = cli_json("equations", FEATURES, "--q", numbers(q), "--qd", numbers(v), "--json")
    assert np.allclose(np.array(cli["M"]), a.M, rtol=0, atol=1e-13 * np.max(np.abs(a.M)))
