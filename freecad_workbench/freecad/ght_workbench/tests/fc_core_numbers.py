"""Writes the core reference numbers computed inside FreeCAD's Python to ``$GHT_FC_OUT/core_numbers.json``."""

from __future__ import annotations

import json
import os
import sys
import unittest

import numpy as np

from freecad.ght_workbench.tests import core_numbers


class CoreNumbersTest(unittest.TestCase):
    def test_write_numbers(self):
        out_dir = os.environ.get("GHT_FC_OUT")
        if not out_dir:
            self.skipTest("GHT_FC_OUT is not set")
        data = core_numbers.compute()
        self.assertIn("curve/p0/d0", data)
        meta = {"numpy": np.__version__, "python": sys.version.split()[0]}
        with open(os.path.join(out_dir, "core_numbers.json"), "w") as fh:
            json.dump({"meta": meta, "numbers": data}, fh)


if __name__ == "__main__":
    unittest.main()
