"""The curves layer (issue 27)."""
