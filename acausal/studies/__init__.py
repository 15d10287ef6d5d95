"""Studies built on simulations: calibration (:mod:`.calibrate`), profile
likelihood (:mod:`.profile`), the next experiment (:mod:`.design`),
parameter sweeps (:mod:`.sweep`) and finite differences
(:mod:`.differences`)."""
