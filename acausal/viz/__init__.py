"""Pictures: result plots (:mod:`.plot`) and planar animations (:mod:`.animate`)."""
