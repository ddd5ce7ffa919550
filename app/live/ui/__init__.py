"""One browser's session and its UI: the session (clock, frame loop, actions), its body and
rebuild, the preset or scene it shows, the control panel and its widgets, the "Motion" window,
the lecture tools, pointing, uploads, links, a phone's page. Everything here runs for one
client; the server's defences are in :mod:`poinsot.app.live.hardening`."""
