"""Exports: DataFrames, xarray, save/load round trips with provenance; pdw's own revision."""
import json
import subprocess
import sys

import numpy as np
import pytest

import pdw
from pdw.core import provenance


@pytest.fixture(scope="module")
def res():
    return pdw.simulate(t_end=1.3, method="rodas4", integrator=pdw.Integrator(rtol=1e-6),
                        record=pdw.Record(energies=True))


def _same_result(a, b):
    for k in ("t", "x", "flags", "Fn", "Ft", "x_final"):
        np.testing.assert_array_equal(getattr(a, k), getattr(b, k), err_msg=k)
    assert a.events == b.events and len(a.events) > 0
    assert a.params == b.params and (a.method, a.variant, a.dt, a.t_end) == (b.method, b.variant, b.dt, b.t_end)
    assert (a.status, a.stop_reason, a.n_gait_steps, a.event_counts) == \
        (b.status, b.stop_reason, b.n_gait_steps, b.event_counts)
    for k in a.gait.table:
        np.testing.assert_array_equal(a.gait[k], b.gait[k])
    for k in a.energies:
        np.testing.assert_array_equal(a.energies[k], b.energies[k])


@pytest.mark.parametrize("ext", ["npz", "nc"])
def test_save_load_round_trip(res, tmp_path, ext):
    if ext == "nc":
        pytest.importorskip("xarray")
        pytest.importorskip("scipy")
    path = res.save(tmp_path / ("run." + ext))
    back = pdw.load(path)
    _same_result(res, back)
    prov = back.provenance["provenance"]
    assert prov["input_hash"] == pdw.INPUT_HASH and prov["pdw_version"] == pdw.__version__
    assert prov["source_revision"] == provenance.source_revision()
    assert back.provenance["units"]["x"]["thetad1"] == "rad/s"


def test_scene_travels_with_the_file(tmp_path):
    scene = pdw.Scene(stop={"t_end": 0.2}, integrator={"method": "rodas4"})
    r = pdw.simulate(scene)
    back = pdw.load(r.save(tmp_path / "s.npz"))
    assert back.provenance["scene"] == scene.to_toml()
    assert pdw.Scene.from_toml(back.provenance["scene"]) == scene


def test_load_refuses_other_files(tmp_path):
    p = tmp_path / "x.npz"
    np.savez(p, meta=np.array(json.dumps({"format": "other"})))
    with pytest.raises(pdw.InvalidInputError, match="not a pdw result"):
        pdw.load(p)
    with pytest.raises(pdw.InvalidInputError, match=".npz or .nc"):
        pdw.load(tmp_path / "x.csv")


def test_dataframes(res):
    pd = pytest.importorskip("pandas")
    df = res.to_dataframe()
    assert isinstance(df, pd.DataFrame) and df.index.name == "t"
    np.testing.assert_array_equal(df.index.values, res.t)
    np.testing.assert_array_equal(df[list(pdw.STATE)].values, res.x)
    np.testing.assert_array_equal(df[["Fn1", "Fn2"]].values, res.Fn)
    np.testing.assert_array_equal(df["E"].values, res.energies["E"])
    assert df.attrs["units"]["theta1"] == "rad" and df.attrs["units"]["Ft2"] == "N"
    sdf = res.gait.to_dataframe()
    assert len(sdf) == len(res.gait) > 0
    np.testing.assert_array_equal(sdf["L"].values, res.gait["L"])
    assert sdf.attrs["units"]["L"] == "m"


def test_xarray(res):
    pytest.importorskip("xarray")
    ds = res.to_xarray()
    assert ds["x"].dims == ("time", "state")
    np.testing.assert_array_equal(ds["x"].sel(state="thetad2").values, res.state("thetad2"))
    np.testing.assert_array_equal(ds["time"].values, res.t)
    assert ds["Fn"].attrs["units"] == "N" and ds["time"].attrs["units"] == "s"
    assert json.loads(ds["x"].attrs["units"])["y_o"] == "m"
    assert ds.attrs["input_hash"] == pdw.INPUT_HASH


def test_source_revision_is_pdws_own_not_the_cwds(tmp_path):
    """From inside another git repository, the revision is still pdw's (or None), never that
    repository's commit."""
    repo = tmp_path / "other"
    repo.mkdir()
    git = ["git", "-C", str(repo), "-c", "user.email=a@b", "-c", "user.name=a"]
    if subprocess.run(git[:3] + ["init", "-q"]).returncode:
        pytest.skip("no git")
    (repo / "f").write_text("x")
    subprocess.run(git + ["add", "f"], check=True)
    subprocess.run(git + ["commit", "-qm", "other"], check=True)
    theirs = subprocess.run(git[:3] + ["rev-parse", "--short", "HEAD"], capture_output=True,
                            text=True).stdout.strip()
    code = "import pdw.core.provenance as p; print(p.source_revision())"
    ours = subprocess.run([sys.executable, "-c", code], cwd=repo, capture_output=True, text=True,
                          check=True).stdout.strip()
    assert theirs not in ours
    # "-dirty" may differ if the working tree is edited while the tests run
    assert ours.removesuffix("-dirty") == str(provenance.source_revision()).removesuffix("-dirty")
    # a copy of the package placed inside that repository (as site-packages in a venv there)
    # is not attributed to it
    fake = repo / "site" / "pdw"
    fake.mkdir(parents=True)
    (fake / "__init__.py").write_text("")
    assert provenance.source_revision(str(fake)) is None


def test_cli_run_writes_the_trajectory(tmp_path):
    from pdw.present import cli
    scene = pdw.Scene(stop={"t_end": 0.5}, integrator={"method": "rodas4"})
    scene.save(tmp_path / "s.toml")
    assert cli.main(["run", str(tmp_path / "s.toml"), "--out", str(tmp_path / "o")]) == 0
    back = pdw.load(tmp_path / "o" / "trajectory.npz")
    ref = pdw.simulate(scene)
    np.testing.assert_array_equal(back.x, ref.x)
    assert pdw.Scene.from_toml(back.provenance["scene"]) == scene
    meta = json.loads((tmp_path / "o" / "run.json").read_text())
    assert meta["provenance"]["input_hash"] == pdw.INPUT_HASH
