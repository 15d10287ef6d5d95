"""Studies built on simulations: the weighted residuals against measured
data (:mod:`.residuals`, shared by the calibration and the diagnosis),
calibration (:mod:`.calibrate`), profile likelihood (:mod:`.profile`), the
next experiment (:mod:`.design`), parameter sweeps (:mod:`.sweep`) and
finite differences (:mod:`.differences`)."""
