# The yardstick of issue 16 ("grading at course scale"): what a plain script needs just to decode
# the same PNG pairs as `goldray grade` and count the differing pixels, with Pillow and numpy, in
# one process. goldray's goal is to grade the class in at most half this time.
#
#   python3 scripts/grade_baseline.py GOLDEN_DIR SUBMISSIONS_DIR
#
# GOLDEN_DIR holds the golden PNGs (a report's golden/ folder, or tests/data/mit6837 for the
# course rubric); SUBMISSIONS_DIR one folder per student, as for `goldray grade`.
import os
import sys
import time

import numpy as np
from PIL import Image

golden, subs = sys.argv[1], sys.argv[2]
start = time.time()
count = 0
files = sorted(f for f in os.listdir(golden) if f.endswith(".png"))
for student in sorted(os.listdir(subs)):
    for f in files:
        a = np.asarray(Image.open(os.path.join(golden, f)).convert("RGB"), dtype=np.int16)
        p = os.path.join(subs, student, f)
        if not os.path.exists(p):
            continue
        b = np.asarray(Image.open(p).convert("RGB"), dtype=np.int16)
        if a.shape == b.shape:
            count += int((np.abs(a - b).max(axis=2) > 8).sum())
print(f"{time.time() - start:.2f} s, {count} differing pixels")
