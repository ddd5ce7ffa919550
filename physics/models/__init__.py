"""The textbook models built on the core: the polhode family, the flip and its
growth, the symmetric top, the gyroscope under torque, the energy sink, the geometric
phase, the racket's twist, the twins, the angles a student reads, the solids."""
