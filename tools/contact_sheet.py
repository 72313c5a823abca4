#!/usr/bin/python3
"""Lays frames out on one labelled contact sheet (docs/contact_sheet.png).

Usage: tools/contact_sheet.py OUT.png COLUMNS LABEL=FRAME.png [LABEL=FRAME.png ...]  (split at the last "=")

Each frame is scaled to a 480 x 270 tile with its label above it. Needs Pillow (Debian's
python3-pil); it is a documentation tool, not part of a run.
"""
import sys

from PIL import Image, ImageDraw

TILE = (480, 270)
LABEL_HEIGHT = 28


def main(argv):
    if len(argv) < 4:
        sys.exit(__doc__.strip().splitlines()[2])
    out, columns, entries = argv[1], int(argv[2]), [a.rsplit("=", 1) for a in argv[3:]]
    rows = (len(entries) + columns - 1) // columns
    sheet = Image.new("RGB", (columns * TILE[0], rows * (TILE[1] + LABEL_HEIGHT)), (245, 245, 240))
    draw = ImageDraw.Draw(sheet)
    for i, (label, path) in enumerate(entries):
        x, y = (i % columns) * TILE[0], (i // columns) * (TILE[1] + LABEL_HEIGHT)
        draw.text((x + 8, y + 8), label, fill=(20, 20, 20))
        sheet.paste(Image.open(path).convert("RGB").resize(TILE), (x, y + LABEL_HEIGHT))
    sheet.save(out, optimize=True)


if __name__ == "__main__":
    main(sys.argv)
