"""The diagnosis's stages, each a function of small dataclasses returning a
new one (:mod:`.chain`), with the worker tasks (:mod:`.tasks`), the fits
(:mod:`.fitting`) and the statistics (:mod:`.stats`)."""
