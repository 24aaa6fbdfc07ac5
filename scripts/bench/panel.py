#!/usr/bin/env python3
"""Side-by-side crops of rendered images, each with its label: the comparison figures of results/.

usage: panel.py OUT.png [--crop X,Y,W,H] [--scale S] [--cols N] LABEL=IMAGE [LABEL=IMAGE ...]

Every IMAGE is cropped to the same rectangle (pixels, from the top left; default: the whole image),
scaled by the integer S with nearest-neighbour pixels (default 1: the rendered pixels as they are), and
placed left to right, N per row (default: all in one row), each with its LABEL in a bar above it.
The pixels are copied, never resampled or re-toned: the panel shows what the renderer wrote.
A missing or unreadable image, a crop outside an image, images of different sizes or OUT among the images
are one-line errors.
"""
import argparse
import os
import sys

from PIL import Image, ImageDraw, ImageFont

LABEL_BAR = 16  # pixels of the label bar above each crop


def fail(msg):
    print(f"panel.py: {msg}", file=sys.stderr)
    sys.exit(1)


def parse_crop(text):
    try:
        x, y, w, h = (int(v) for v in text.split(","))
    except ValueError:
        fail(f"--crop '{text}': expected X,Y,W,H (integers)")
    if x < 0 or y < 0 or w <= 0 or h <= 0:
        fail(f"--crop '{text}': X and Y must be >= 0, W and H > 0")
    return x, y, w, h


def load(spec):
    if "=" not in spec:
        fail(f"'{spec}': expected LABEL=IMAGE")
    label, path = spec.split("=", 1)
    try:
        with Image.open(path) as im:
            return label, im.convert("RGB")
    except (OSError, ValueError) as e:
        fail(f"{path}: {e}")


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("out")
    ap.add_argument("images", nargs="+", metavar="LABEL=IMAGE")
    ap.add_argument("--crop", type=parse_crop)
    ap.add_argument("--scale", type=int, default=1)
    ap.add_argument("--cols", type=int, default=0)
    a = ap.parse_args()
    if a.scale < 1 or a.scale > 16:
        fail("--scale must be in [1, 16]")
    if any(os.path.realpath(s.split("=", 1)[-1]) == os.path.realpath(a.out) for s in a.images):
        fail(f"{a.out}: is one of the images (the panel never replaces its inputs)")
    tiles = [load(s) for s in a.images]
    size = tiles[0][1].size
    for _, im in tiles:
        if im.size != size:
            fail(f"images of different sizes: {size} and {im.size}")
    x, y, w, h = a.crop if a.crop else (0, 0, size[0], size[1])
    if x + w > size[0] or y + h > size[1]:
        fail(f"--crop {x},{y},{w},{h} leaves the {size[0]}x{size[1]} image")
    cols = a.cols if a.cols > 0 else len(tiles)
    rows = (len(tiles) + cols - 1) // cols
    tw, th = w * a.scale, h * a.scale
    panel = Image.new("RGB", (cols * tw, rows * (th + LABEL_BAR)), (255, 255, 255))
    draw = ImageDraw.Draw(panel)
    font = ImageFont.load_default()
    for i, (label, im) in enumerate(tiles):
        px, py = (i % cols) * tw, (i // cols) * (th + LABEL_BAR)
        crop = im.crop((x, y, x + w, y + h)).resize((tw, th), Image.NEAREST)
        panel.paste(crop, (px, py + LABEL_BAR))
        draw.text((px + 3, py + 2), label, fill=(0, 0, 0), font=font)
    try:
        panel.save(a.out)
    except (OSError, ValueError) as e:
        fail(f"{a.out}: {e}")
    print(f"{a.out}: {len(tiles)} crops of {w}x{h} at ({x}, {y}), x{a.scale}, {cols} per row")


if __name__ == "__main__":
    main()
