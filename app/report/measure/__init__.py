"""The work-precision study's measurements: the cases, the high-precision reference, the runs and
their timing, the conditioning, the speed-up, the game engines' steps and the study that ties
them."""
