"""Plane geometry shared by the planar components (the frame convention:
acausal/connectors.py, ``Frame``)."""
import sympy as sp
from sympy import cos, sin, sqrt


def rotate(phi, rx, ry):
    """World components of the vector (rx, ry) given in a frame at angle phi."""
    return cos(phi) * rx - sin(phi) * ry, sin(phi) * rx + cos(phi) * ry


def column(joint):
    """('r', x, y) of a revolute's pin or ('p', ux, uy) of a prismatic's
    world axis, as expressions of the joint's frame_a."""
    a = joint.frame_a
    if joint.coordinate == "phi":
        return "r", a.x, a.y
    n = sqrt(joint.ex**2 + joint.ey**2)
    ux, uy = rotate(a.phi, joint.ex / n, joint.ey / n)
    return "p", ux, uy


def minor_sine(cols):
    """The normalised minor of three joint columns, or None when it has no
    revolute (three sliders: singular whatever the configuration).

    Three revolutes: twice the area of their triangle over the product of
    its two shorter sides (all three over the longest), the sine of the bend
    at the middle joint (0 in line). A slider among them: the sine of the
    angle between the revolutes' offset turned by 90 deg and the axis (or
    between two axes)."""
    revs = [c for c in cols if c[0] == "r"]
    if not revs:
        return None
    o = revs[0]
    vecs = []
    for c in cols:
        if c is o:
            continue
        vecs.append((c[2] - o[2], -(c[1] - o[1])) if c[0] == "r" else (c[1], c[2]))
    (a1, a2), (b1, b2) = vecs
    det = a1 * b2 - a2 * b1
    la, lb = sqrt(a1**2 + a2**2), sqrt(b1**2 + b2**2)
    if len(revs) < 3:
        return det / (la * lb)
    lc = sqrt((a1 - b1)**2 + (a2 - b2)**2)
    # the longest side as a Piecewise, not sp.Max: Max orders its arguments
    # symbolically at every construction and every xreplace (0.16 s each on
    # the planar breaker's four-bar: half of each model build's 17 s CPU)
    longest = sp.Piecewise((la, sp.And(la >= lb, la >= lc)), (lb, lb >= lc), (lc, True))
    return det * longest / (la * lb * lc)
