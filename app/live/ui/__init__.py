"""One browser's session and its UI: the session (state, clock, frame loop), the control
panel and its widgets, the "Motion" window, the lecture tools, pointing, uploads, links, a
phone's page. Everything here runs for one client; the server's defences are in
:mod:`poinsot.app.live.hardening`."""
