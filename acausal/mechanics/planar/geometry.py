"""Plane geometry shared by the planar components (the frame convention:
acausal/connectors.py, ``Frame``)."""
from sympy import cos, sin


def rotate(phi, rx, ry):
    """World components of the vector (rx, ry) given in a frame at angle phi."""
    return cos(phi) * rx - sin(phi) * ry, sin(phi) * rx + cos(phi) * ry
