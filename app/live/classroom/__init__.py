"""The classroom: links to a state, following the lecturer (`follow.py`: the hub of one process) and
leading (`lead.py`: the "Class" folder)."""
