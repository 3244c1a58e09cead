"""The core layer (issue 27)."""
