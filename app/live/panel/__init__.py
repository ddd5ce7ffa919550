"""The control panel and its widgets: the body's controls, every value checked against its widget,
the "Motion" window (plots, readouts, legend, an uploaded toss's overlay), a scene's own widgets,
uploads, the numerical ghost's controls, the clock and playback."""
