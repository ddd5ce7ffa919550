"""The server's hardening: what keeps one misbehaving or slow client from hurting the
others: the wire guard, each client's message budget and backlog, per-client frame pacing,
the rebuild gate, the upkeep, the bounded transfers, the network checks, and the websocket
probe that tests and benchmarks speak viser's protocol with."""
