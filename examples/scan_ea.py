"""A parameter scan over the rope's axial stiffness EA, in-process: the paper's scene run
for 2 s at four values of EA, the peak tension of each.

    python examples/scan_ea.py
"""
import math
import pathlib

import ropedyn

scene = ropedyn.Scene.from_file(pathlib.Path(__file__).resolve().parents[1] / "input" / "paper.nml")
scene.set("solver.t_end", 2.0)
area = math.pi * scene.get("rope.diameter") ** 2 / 4
for ea in (100.0, 300.0, 1000.0, 3000.0):                    # N
    run = ropedyn.run(scene.copy().set("rope.young_modulus", ea / area))
    print(f"EA = {ea:6.0f} N: peak tension {run.forces['axial'].max():.3f} N")
