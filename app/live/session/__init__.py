"""One browser's session and its frame loop: the `Session` composed of its queue of actions, its
frame thread, its body's rebuild, the preset or scene it shows and the refreshes after each
frame."""
