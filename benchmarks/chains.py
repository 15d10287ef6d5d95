"""Scalable test mechanisms for the scaling benchmark and the large-model
tests: a chain of N masses joined by springs (and dampers), one end fixed.

Ball/mass k is ``m{k}``; spring k joins mass k-1 (or the fixed end, k = 0)
to mass k. All springs start relaxed except the last mass, which starts
displaced by ``ds``; the exact small-time behaviour is not needed here, only
a model whose size grows linearly with N.
"""
from acausal import Model
from acausal.mechanics.translational import Fixed, Mass, SpringDamper


def chain(n, m=1.0, c=1e4, d=1.0, ds=0.01):
    """A chain of ``n`` masses [kg] ``m`` joined by spring-dampers ``c`` [N/m],
    ``d`` [N*s/m]; mass 0 is tied to a fixed point; the last mass starts
    displaced by ``ds`` [m]."""
    model = Model()
    model.add("ground", Fixed())
    prev = model.ground.flange
    for k in range(n):
        s0 = ds if k == n - 1 else 0.0
        mass = model.add(f"m{k}", Mass(m=m, s=s0, v=0.0))
        spring = model.add(f"k{k}", SpringDamper(c=c, d=d))
        model.connect(prev, spring.flange_a)
        model.connect(spring.flange_b, mass.flange)
        prev = mass.flange
    return model
