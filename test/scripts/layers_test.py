#!/usr/bin/python3
"""The include graph of src/ and include/ points only down the layers (docs/architecture.md):
ros and the tools use the scene kinds, the kinds use the run layer (the run loop, measures and fixes),
the run layer uses the file readers (io), and everything uses the core; never the other way."""
import os
import re
import unittest

ROOT = os.path.abspath(os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", ".."))
# Layer of each folder of src/ and include/regolith_twin/ (a folder may include its own layer and below).
LAYERS = {"core": 0, "io": 1, "validate": 1, "run": 2, "observers": 2, "scenes": 3, "ros": 4, "tools": 5}
INCLUDE = re.compile(r'^\s*#\s*include\s+"regolith_twin/([a-z_]+)/', re.M)


def upward(folder, text):
    """The folders that `text`, a file of `folder`, includes from a higher layer."""
    return sorted({f for f in INCLUDE.findall(text) if LAYERS.get(f, 99) > LAYERS[folder]})


def files():
    for base in (os.path.join(ROOT, "src"), os.path.join(ROOT, "include", "regolith_twin")):
        for folder in sorted(os.listdir(base)):
            top = os.path.join(base, folder)
            if not os.path.isdir(top):
                continue
            for d, _, names in os.walk(top):
                for n in names:
                    if n.endswith((".cpp", ".hpp")):
                        yield folder, os.path.join(d, n)


class Layers(unittest.TestCase):
    def test_every_folder_has_a_layer(self):
        self.assertEqual(sorted({f for f, _ in files()} - set(LAYERS)), [])

    def test_no_include_points_up_a_layer(self):
        bad = []
        for folder, path in files():
            with open(path) as f:
                up = upward(folder, f.read())
            if up:
                bad.append("%s includes %s" % (os.path.relpath(path, ROOT), ", ".join(up)))
        self.assertEqual(bad, [])

    def test_the_check_sees_an_upward_include(self):
        self.assertEqual(upward("run", '#include "regolith_twin/scenes/landing/landing.hpp"\n'), ["scenes"])
        self.assertEqual(upward("core", '  #include "regolith_twin/io/scenario.hpp"\n'), ["io"])
        self.assertEqual(upward("scenes", '#include "regolith_twin/run/run.hpp"\n'), [])


if __name__ == "__main__":
    unittest.main()
