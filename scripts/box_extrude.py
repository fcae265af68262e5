"""The script a historian would write instead of edo-city: every lot extruded to a 7 m box,
one OBJ. The yardstick of `make bench` (issue 25): edo-city with its default features must
be faster than this, and within 2x of it with every feature on.

    python3 scripts/box_extrude.py TOWN/lots.shp OUT.obj   (pyshp: make bench puts it in target/bench-venv)
"""
import sys

import shapefile

HEIGHT = 7.0


def main(src, dst):
    reader = shapefile.Reader(src)
    with open(dst, "w") as out:
        n = 0
        for shape in reader.iterShapes():
            ring = shape.points[: shape.parts[1] if len(shape.parts) > 1 else None]
            if len(ring) > 1 and ring[0] == ring[-1]:
                ring = ring[:-1]
            k = len(ring)
            for x, y in ring:
                out.write(f"v {x:.3f} 0 {-y:.3f}\nv {x:.3f} {HEIGHT} {-y:.3f}\n")
            for i in range(k):
                a, b = n + 2 * i + 1, n + 2 * ((i + 1) % k) + 1
                out.write(f"f {a} {b} {b + 1} {a + 1}\n")
            out.write("f " + " ".join(str(n + 2 * i + 2) for i in range(k)) + "\n")
            out.write("f " + " ".join(str(n + 2 * i + 1) for i in reversed(range(k))) + "\n")
            n += 2 * k


if __name__ == "__main__":
    main(sys.argv[1], sys.argv[2])
