"""The solver core: one free rigid body, classified once (exact integers) and
evaluated on whole time arrays, with the elliptic functions, the closed forms, the
arithmetic, the rotations, the error measures and every input check it rests on."""
