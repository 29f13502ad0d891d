"""Write the square-tube crush deck: a thin-walled steel tube (Belytschko-Tsay shells,
*MAT_PIECEWISE_LINEAR_PLASTICITY) standing on a fixed rigid wall and crushed axially by a moving
rigid wall, with single-surface contact between its folds.

Usage: python3 generate_tube.py [--element SIZE] [--crush DEPTH] [--output tube.k]

Units: mm, ms, kg, kN, GPa (stress in GPa = kN/mm^2).
The tube is C x C in section (mid-surface), length L, wall t, along z. The moving wall starts
at the top end and moves down at `speed`; the bottom end rests on a stationary wall. A small
inward dent (a geometric trigger, as crash engineers put in real rails) starts the first fold
near the top so that the progressive folding starts where the wall is.
"""
import argparse
import math

parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
parser.add_argument("--element", type=float, default=2.5, help="element size in mm (default 2.5)")
parser.add_argument("--side", type=float, default=50.0, help="section width C in mm (default 50)")
parser.add_argument("--length", type=float, default=200.0, help="tube length L in mm (default 200)")
parser.add_argument("--thickness", type=float, default=1.5, help="wall thickness t in mm (default 1.5)")
parser.add_argument("--speed", type=float, default=10.0, help="wall speed in mm/ms = m/s (default 10)")
parser.add_argument("--crush", type=float, default=100.0, help="crush distance in mm (default 100)")
parser.add_argument("--nip", type=int, default=5, help="through-thickness points (default 5)")
parser.add_argument("--output", default="tube.k")
args = parser.parse_args()

C, L, t, h = args.side, args.length, args.thickness, args.element
per_side = max(2, round(C / h))
around = 4 * per_side
along = max(4, round(L / h))
end_time = args.crush / args.speed

# mid-surface points around the section, counter-clockwise, starting at a corner
ring = []
for side in range(4):
    for k in range(per_side):
        s = k / per_side
        corners = [(-C / 2, -C / 2), (C / 2, -C / 2), (C / 2, C / 2), (-C / 2, C / 2)]
        (x0, y0), (x1, y1) = corners[side], corners[(side + 1) % 4]
        ring.append((x0 + s * (x1 - x0), y0 + s * (y1 - y0), side, k))

def node_id(i, j):
    return j * around + i + 1

# trigger: two opposite faces dented inward by 0.1 t near the top (a cosine bump over one fold)
fold = 0.5 * math.sqrt(C * t) * 3.0   # about the half-wavelength of the first fold
lines = ["*KEYWORD", "*TITLE", f"square tube {C:g} x {t:g} mm crushed at {args.speed:g} m/s",
         "*CONTROL_TERMINATION", f"{end_time:10.4f}",
         "*CONTROL_TIMESTEP", "         0       0.9",
         "*CONTROL_HOURGLASS", "         4       0.1",
         "*CONTROL_CONTACT", "       0.1",
         "*DATABASE_GLSTAT", f"{end_time / 500:10.5f}",
         "*DATABASE_MATSUM", f"{end_time / 500:10.5f}",
         "*DATABASE_RWFORC", f"{end_time / 1000:10.6f}",
         "*DATABASE_RCFORC", f"{end_time / 500:10.5f}",
         "*DATABASE_BINARY_D3PLOT", f"{end_time / 10:10.5f}",
         "*NODE"]
for j in range(along + 1):
    z = L * j / along
    for i, (x, y, side, k) in enumerate(ring):
        dent = 0.0
        if side in (0, 2) and L - z < 2 * fold:
            dent = 0.1 * t * 0.5 * (1 - math.cos(math.pi * (L - z) / fold)) * math.sin(math.pi * k / per_side)
        nx, ny = (0.0, 1.0) if side == 0 else (0.0, -1.0) if side == 2 else (0.0, 0.0)
        lines.append(f"{node_id(i, j):8d}{x + dent * nx:16.9e}{y + dent * ny:16.9e}{z:16.9e}{0:8d}{0:8d}")
lines += ["*PART", "tube", f"{1:10d}{1:10d}{1:10d}",
          "*SECTION_SHELL", f"{1:10d}{2:10d}{5 / 6:10.6f}{args.nip:10d}", f"{t:10.4f}{t:10.4f}{t:10.4f}{t:10.4f}",
          "*MAT_PIECEWISE_LINEAR_PLASTICITY",
          f"{1:10d}{7.85e-6:10.3e}{210.0:10.3f}{0.3:10.3f}{0.0:10.4f}{0.0:10.4f}",
          f"{0.0:10.1f}{0.0:10.1f}{1:10d}{0:10d}",
          "", "",
          "*DEFINE_CURVE_TITLE", "mild steel: true stress (GPa) against effective plastic strain", f"{1:10d}"]
# mild steel, yield 0.25 GPa, saturating hardening (a Voce fit of typical DC04-like data)
for strain in [0.0, 0.01, 0.02, 0.05, 0.1, 0.2, 0.3, 0.5, 1.0]:
    stress = 0.25 + 0.15 * (1 - math.exp(-strain / 0.08))
    lines.append(f"{strain:20.6f}{stress:20.6f}")
lines += ["*ELEMENT_SHELL"]
e = 0
for j in range(along):
    for i in range(around):
        e += 1
        i2 = (i + 1) % around
        lines.append(f"{e:8d}{1:8d}{node_id(i, j):8d}{node_id(i2, j):8d}{node_id(i2, j + 1):8d}{node_id(i, j + 1):8d}")
lines += ["*CONTACT_AUTOMATIC_SINGLE_SURFACE_ID", f"{1:10d}{'':70s}tube folds",
          f"{1:10d}{0:10d}{3:10d}{0:10d}",
          f"{0.2:10.3f}{0.2:10.3f}",
          "",
          # stationary base wall under the bottom end, moving wall on the top end
          "*RIGIDWALL_PLANAR_ID", f"{1:10d}{'':70s}base", f"{0:10d}",
          f"{0.0:10.3f}{0.0:10.3f}{-0.01:10.3f}{0.0:10.3f}{0.0:10.3f}{1.0:10.3f}{0.2:10.3f}",
          "*RIGIDWALL_PLANAR_MOVING_ID", f"{2:10d}{'':70s}crushing wall", f"{0:10d}",
          f"{0.0:10.3f}{0.0:10.3f}{L + 0.01:10.3f}{0.0:10.3f}{0.0:10.3f}{L - 1.0:10.3f}{0.2:10.3f}",
          f"{500.0:10.3f}{args.speed:10.3f}",
          "*END"]
with open(args.output, "w") as deck:
    deck.write("\n".join(lines) + "\n")
print(f"{args.output}: {e} shells, {(along + 1) * around} nodes, end time {end_time:g} ms")
