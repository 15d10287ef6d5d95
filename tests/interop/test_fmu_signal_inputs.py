"""An input connector that nothing sets (MSL's RealInput left open at the
top level) becomes an FMU input: a mass pushed by ``Force()`` whose force
signal the importer drives. Needs the causal signal connectors
(acausal.blocks); skipped before they are there."""
import numpy as np
import pytest

fmpy = pytest.importorskip("fmpy", reason="needs the fmu extra: pip install -e '.[fmu]'")
pytest.importorskip("acausal.blocks", reason="needs the causal signal connectors")

from fmpy.validation import validate_fmu  # noqa: E402

from acausal.interop.fmu import export_fmu  # noqa: E402

MODEL = """
from acausal import Experiment, Model
from acausal.mechanics.translational import Force, Mass

model = Model()
model.body = Mass(m=2.0, s=0.0, v=0.0)
model.force = Force()                  # its input f is left open: the FMU's input
model.connect(model.force.flange, model.body.flange)
experiment = Experiment(t_end=1.0, rtol=1e-8, atol=1e-10)
"""


def test_open_force_input_drives_the_mass(tmp_path):
    path = tmp_path / "pushed.py"
    path.write_text(MODEL)
    fmu = export_fmu(path, tmp_path / "pushed.fmu", outputs=["body.s", "body.v"])
    assert validate_fmu(fmu) == []
    md = fmpy.read_model_description(fmu)
    v = {sv.name: sv for sv in md.modelVariables}
    assert (v["force.f"].causality, v["force.f"].unit) == ("input", "N")
    assert not any(n.startswith("fmu_input_") for n in v)   # the parameter behind it is hidden
    F, t1, m = 10.0, 0.5, 2.0
    inp = np.array([(0.0, 0.0), (t1, 0.0), (t1, F), (1.0, F)],
                   dtype=[("time", float), ("force.f", float)])
    r = fmpy.simulate_fmu(fmu, output_interval=0.01, input=inp)
    t = r["time"]
    exact_s = np.where(t <= t1, 0.0, F / (2 * m) * (t - t1) ** 2)    # m s'' = f
    exact_v = np.where(t <= t1, 0.0, F / m * (t - t1))
    assert np.max(np.abs(r["body.s"] - exact_s)) / np.ptp(exact_s) < 1e-6
    assert np.max(np.abs(r["body.v"] - exact_v)) / np.ptp(exact_v) < 1e-6
