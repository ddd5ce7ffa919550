"""A start pointed at: one drag-and-release pointer for any pointable surface (the ellipsoid), and
Landau's momentum sphere."""
