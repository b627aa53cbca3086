#!/usr/bin/env python3
"""Writes a scene of head.json's volume and cameras with N labels at random anchors in the head
(uniform in an ellipsoid inside the brain of ch2.nii.gz), for placement benchmarks.

    scripts/make-random-labels.py N OUT.json [--seed S]

OUT.json should sit in assets/scenes/ (its paths are relative to that folder)."""
import argparse
import json
import math
import random


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("count", type=int)
    parser.add_argument("out")
    parser.add_argument("--seed", type=int, default=1)
    args = parser.parse_args()
    if not 1 <= args.count <= 4096:
        parser.error("N: 1 to 4096 labels")
    with open(__file__.rsplit("/", 2)[0] + "/assets/scenes/head.json", encoding="utf-8") as f:
        head = json.load(f)
    rng = random.Random(args.seed)
    centre, radii = (0.0, 10.0, 15.0), (60.0, 80.0, 60.0)  # LPS mm, inside the brain
    labels = []
    while len(labels) < args.count:
        u = [rng.uniform(-1.0, 1.0) for _ in range(3)]
        if sum(x * x for x in u) > 1.0:
            continue
        anchor = [round(c + r * x, 2) for c, r, x in zip(centre, radii, u)]
        words = rng.randint(1, 3)
        text = " ".join(rng.choice(WORDS) for _ in range(words))
        labels.append({"id": len(labels) + 1, "text": text, "anchor": anchor})
    scene = {"strata_scene": 1, "volumes": head["volumes"], "camera": head["camera"],
             "settings": head["settings"], "labels": labels}
    with open(args.out, "w", encoding="utf-8") as f:
        json.dump(scene, f, indent=1)
        f.write("\n")


WORDS = ["lesion", "cyst", "node", "vessel", "nerve", "gyrus", "sulcus", "tract", "nucleus",
         "fissure", "horn", "lobe", "canal", "foramen", "sinus", "ventricle", "duct", "clot"]

if __name__ == "__main__":
    main()
