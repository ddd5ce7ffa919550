"""Offline exports: CSV, GLB, standalone HTML and PNG screenshots."""
