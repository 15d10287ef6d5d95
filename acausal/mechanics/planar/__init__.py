"""Planar (2-D) multibody mechanics: frames, bodies, joints, line forces and
adaptors to the 1-D flanges. Sign convention and the picture of a frame:
:mod:`acausal.connectors` (:class:`~acausal.connectors.Frame`).

One small module per kind: :mod:`.partials` (connector equations),
:mod:`.parts` (Fixed, Body, FixedTranslation), :mod:`.joints` (Revolute,
Prismatic), :mod:`.forces` (Spring, Damper, SpringDamper between frames),
:mod:`.adaptors` (frame <-> rotational / translational flange),
:mod:`.contact` (a circle against a line or a circle) and :mod:`.polyline`
(a circle against a polyline profile).
"""
