# A synthetic class for measuring `goldray grade` at course scale (issue 16): STUDENTS folders,
# each holding the golden images of a rubric perturbed per image: 60% identical, 25% with 200
# scattered pixels changed by 40 codes (they still pass), 15% with a band of 120 rows darkened
# (they fail). Deterministic (fixed seed). For the course rubric (21 images at 800×800):
#
#   mkdir empty && goldray grade --rubric rubrics/mit6837.toml empty --out goldens   # goldens/golden/*.png
#   python3 scripts/make_class.py goldens/golden class 20
#   goldray grade --rubric rubrics/mit6837.toml class --out report
#   python3 scripts/grade_baseline.py goldens/golden class
import os
import sys

import numpy as np
from PIL import Image

reference, out = sys.argv[1], sys.argv[2]
students = int(sys.argv[3]) if len(sys.argv) > 3 else 20
rng = np.random.default_rng(16)
files = sorted(f for f in os.listdir(reference) if f.endswith(".png"))
for s in range(students):
    folder = os.path.join(out, f"student{s:02d}")
    os.makedirs(folder, exist_ok=True)
    for f in files:
        picture = np.asarray(Image.open(os.path.join(reference, f)).convert("RGB")).copy()
        kind = rng.random()
        if kind >= 0.85:
            top = int(rng.integers(0, picture.shape[0] - 120))
            picture[top : top + 120] //= 2
        elif kind >= 0.6:
            ys = rng.integers(0, picture.shape[0], 200)
            xs = rng.integers(0, picture.shape[1], 200)
            picture[ys, xs] = (picture[ys, xs].astype(np.int16) + 40).clip(0, 255).astype(np.uint8)
        Image.fromarray(picture).save(os.path.join(folder, f))
