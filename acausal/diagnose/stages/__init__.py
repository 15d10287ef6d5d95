"""The diagnosis's stages, each a function of small dataclasses returning a
new one (:mod:`.chain` and one module per later stage), run with a
:class:`.context.Context` over a :class:`.state.State`; the worker tasks
(:mod:`.tasks`), the fits (:mod:`.fitting`) and the statistics
(:mod:`.stats`)."""
