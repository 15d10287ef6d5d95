"""latch_striker.py extended by the hypothesis 'coulomb_friction' at 'latch'.

Coulomb (dry) friction at a joint. A constant-magnitude friction force (torque) at the guide (bearing) of the body opposes its motion whatever the speed: it removes energy in proportion to the travel and delays slow motions more than fast ones.

Law: f = -F*tanh(v/v_eps) on the body against the frame: kinetic Coulomb friction of level F opposing the velocity, regularised over |v| < v_eps (v_eps = 1e-3 x the body's peak nominal speed; no stiction).
Values:
    hyp_cf.F = 1.7351 [N]  (Coulomb friction level at the guide of latch)

Written by acausal.diagnose.write_extended_model; run it with
`acausal simulate latch_striker_coulomb_friction.py`.
"""
import os as _os

from acausal.modelfile import load_model_file as _load_model_file

_base = _load_model_file(_os.path.join(_os.path.dirname(_os.path.abspath(__file__)), '../models/latch_striker.py'))
model = _base.model
experiment = _base.experiment
measures = dict(_base.measures)
free_parameters = dict(_base.free)
free_parameters.update({'hyp_cf.F': (0.0, 5.790268426012585)})
plot = _base.namespace.get("plot")

# calibrated free parameters (acausal diagnose)
model.find('contact').set(K=496938432.9361257)
model.find('latch_damper').set(d=4.768260920473913)

# hypothesis coulomb_friction at latch: Coulomb (dry) friction at a joint
#   f = -F*tanh(v/v_eps) on the body against the frame: kinetic Coulomb friction of level F opposing the velocity, regularised over |v| < v_eps (v_eps = 1e-3 x the body's peak nominal speed; no stiction)
from acausal.diagnose.hypotheses import HYPOTHESES as _HYPOTHESES
hypothesis_specs = _HYPOTHESES['coulomb_friction'].apply(model, 'latch', {'hyp_cf.F': 1.7350990637573322, 'hyp_cf.v_eps': 0.0015218762664569794})
