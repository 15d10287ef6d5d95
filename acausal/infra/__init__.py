"""Infrastructure shared by the layers above: the on-disk store
(:mod:`.store`), checkpoints of long commands (:mod:`.checkpoint`), the
process and Dask executors (:mod:`.executor`) and BLAS thread limits
(:mod:`.blas`). Nothing here imports the modelling language, the compiler
or the runtime."""
