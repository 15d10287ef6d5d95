"""The latch striker on synthetic data holding a Coulomb friction at the
latch that its nominal model lacks (two coil forces, the latch's travel at
5 kHz): the small real problem of the fit tests (``test_lone_fit``,
``test_fit_budget``)."""
import os

from acausal.diagnose.stages.chain import load_problem
from acausal.diagnose.synth import synthesize

LATCH = os.path.abspath(os.path.join(os.path.dirname(__file__), "..", "..", "models",
                                     "latch_striker.py"))


def latch_friction_problem(folder, seed):
    """The :class:`~acausal.diagnose.problem.Problem` of the latch against
    data synthesized into ``folder`` with noise ``seed``."""
    synthesize(LATCH, folder, hypothesis="coulomb_friction", location="latch",
               effect=(6.0, 6.0), conditions={"F_coil": [20.0, 45.0]}, traces=["latch.s"],
               sample_rate=5e3, noise={"latch.s": 5e-6}, resolution={"latch.s": 5e-6},
               units={"time": "ms", "latch.s": "mm"}, seed=seed)
    return load_problem(LATCH, folder)[0]
