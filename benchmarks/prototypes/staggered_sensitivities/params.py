from common import *
from acausal.diagnose.stages.locate import _graph, _params
graph = _graph(problem)
wparams = _params(graph, node, nx, nv)
free = problem.free
PAR = {q.name: q for q in list(free) + list(wparams)}
NAMES = list(vals)            # order of candidates.json values: spring.c, bearing.d, gen.a*, gen.b*
PART_VARS = {"a": "motor.phi", "b": "motor.w"}
