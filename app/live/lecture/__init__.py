"""The lecture tools: exports and views, the theme and projector mode, a phone's or tablet's page,
video and strobe, the predict-then-play challenges, a neighbour of any preset."""
