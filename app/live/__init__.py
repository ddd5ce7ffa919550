"""The live server: one session per browser, its panel, clock and frame loop."""
