"""Developer tools over the whole physics: the fuzz of the public API
(``python -m poinsot.physics.tools.fuzz``) and the benchmark
(``python -m poinsot.physics.tools.benchmark``)."""
