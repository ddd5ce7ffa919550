"""The work-precision study behind ``poinsot report`` (never imports viser)."""
