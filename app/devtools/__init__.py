"""Developer tools: the benchmark of the live path (`benchmark.py`, `drag_benchmark.py`), the
comparison of this tree against another revision (`compare.py`), the classroom load test (`load/`)
and the websocket client that speaks viser's protocol for them and for the tests (`probe.py`)."""
