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


def test_validate_checks_the_file_it_was_loaded_from_as_the_cli_does():
    """femdyn.validate of a model loaded from an MJCF or URDF file has the CLI's rows against
    that file ('mujoco', 'import'), with the same numbers at the same seed."""
    import warnings

    loops = ROOT / "tests" / "data" / "mjcf" / "loops.xml"
    arm = ROOT / "models" / "urdf" / "arm7.urdf"
    for path, row in ((loops, "mujoco"), (arm, "import")):
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            py = femdyn.validate(femdyn.load(str(path)), t_end=0)
        cli = cli_json("validate", path, "--t-end", "0", "--json")
        assert py["pass"] and cli["pass"]
        assert row in py["quantities"], f"{path.name}: no {row!r} row in Python"
        assert py["quantities"][row]["max_rel"] == cli["max_rel_error"][row]
