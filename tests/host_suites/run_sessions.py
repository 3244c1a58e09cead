"""Run several pytest sessions on the same host test modules one after the other in ONE interpreter
(tests/test_host_suites.py): the host (build123d with OCP, sklearn, ...) is imported once instead
of once per session, which was most of each session's time.

Usage: ``python run_sessions.py '<json [[junit_xml, plugin or null], ...]>' <pytest args and modules>``.
A session without a plugin must come before any session with one: it runs with no ght_cad module
imported (checked here), as a fresh interpreter would.
"""

import json
import sys

import pytest


def _ght_loaded() -> list[str]:
    return sorted(m for m in sys.modules if m == "ght_cad" or m.startswith("ght_cad."))


def main() -> int:
    sessions = json.loads(sys.argv[1])
    args = sys.argv[2:]
    for xml, plugin in sessions:
        if plugin is None and _ght_loaded():
            raise SystemExit(f"a plain session after ght_cad was imported ({_ght_loaded()[:3]}): put it first")
        pytest.main([f"--junitxml={xml}"] + (["-p", plugin] if plugin else []) + args)
    return 0


if __name__ == "__main__":
    sys.exit(main())
