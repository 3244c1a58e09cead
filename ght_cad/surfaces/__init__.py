"""The surfaces layer (issue 27)."""
