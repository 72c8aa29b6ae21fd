#!/usr/bin/python3
"""Writes a contact job for a masonry wall: rows of bricks in a running bond (every other row shifted by half a
brick, with half bricks at its ends) on a clamped base, pressed from above by a uniform pressure on the top row.
The bed joints are contacts: a brick's bottom edge against the top edge of each brick it rests on, listed
explicitly as pairs.

    scripts/make_brick_wall.py [--rows 8] [--bricks 8] [--cells 4] [--abutments | --head-joints]
                               [--friction MU [--shear S]] [-o api/examples/brick_wall.json]

Frictionless (the default): each brick is held sideways at one corner (a dowel: x fixed at its bottom-left vertex)
and otherwise floats - its vertical position and its rotation are held by its contacts alone - so the job
exercises many-body contact and the floating-body equilibrium far past three bodies. The default, 8 rows of 8
bricks, has 68 bricks, 69 bodies and 120 contact pairs (docs/parallel.md).

With --abutments the bricks have no dowels: two clamped side walls (abutments) and head joints (each brick's right
edge against the next one's left edge, the end bricks against the abutments) hold them sideways, so every brick
floats in all three rigid motions and every head joint is a zero-gap contact closed by the Poisson expansion under
the load alone (8 x 8: 71 bodies, 196 pairs). --head-joints gives the head joints between the bricks without the
abutments (the ends of every course free).

Masonry (docs/friction.md): --friction MU makes every joint a Coulomb contact with coefficient MU and removes the
dowels: friction alone holds the bricks sideways (--head-friction gives the head joints their own coefficient, 0
for frictionless ones). The load is then a path of two steps: the precompression (the
top pressure) in step 1, held in step 2 while a horizontal point load at the top-left corner of every top-row
brick grows from 0 to --shear S times that brick's vertical load (its `history`). Statics: every bed joint carries
the shear S V over the normal load V, so no wall holds for S > MU (and some fail below it, by rocking end stones over
a stepped crack). --collapse asks instead for the collapse analysis (docs/limit-analysis.md): the precompression
held, the shear a live load whose multiplier is S, raised to the largest S the wall holds."""
import argparse
import json
import sys


def wall(rows, bricks, cells, length=0.24, height=0.07, pressure=2.0, abutments=False, head_joints=False,
         friction=None, shear=0.0, head_friction=None, collapse=False):
    E, nu = 1.0e4, 0.2            # MPa: brick
    E_base, nu_base = 3.0e4, 0.2  # concrete base
    width = bricks * length
    dowels = not abutments and friction is None
    bodies, contacts = [], []

    def brick(name, x0, y0, x1, y1, nx):
        bodies.append({"name": name, "material": {"E": E, "nu": nu},
                       "mesh": {"block": {"corners": [[x0, y0], [x1, y0], [x1, y1], [x0, y1]], "nx": nx,
                                          "ny": max(1, cells // 2)}},
                       "boundary": [{"vertex": "bottom_left", "displacement": {"x": 0}}] if dowels else []})

    base_t = 0.1
    bodies.append({"name": "base", "material": {"E": E_base, "nu": nu_base},
                   "mesh": {"block": {"corners": [[-0.1, -base_t], [width + 0.1, -base_t], [width + 0.1, 0], [-0.1, 0]],
                                      "nx": 4 * bricks, "ny": 2}},
                   "boundary": [{"edge": "bottom", "displacement": {"x": 0, "y": 0}}]})

    layout = []  # per row: list of (name, x0, x1)
    for r in range(rows):
        y0, y1 = r * height, (r + 1) * height
        xs = [i * length for i in range(bricks + 1)]
        if r % 2 == 1:  # running bond: half bricks at both ends
            xs = [0.0] + [(i + 0.5) * length for i in range(bricks)] + [width]
        row = []
        for i in range(len(xs) - 1):
            name = f"b{r}_{i}"
            half = xs[i + 1] - xs[i] < 0.75 * length
            brick(name, xs[i], y0, xs[i + 1], y1, max(1, cells // 2) if half else cells)
            row.append((name, xs[i], xs[i + 1]))
        layout.append(row)

    def pair(slave, master, mu=friction):
        contact = {"slave": slave, "master": master}
        if mu:
            contact["friction"] = {"coefficient": mu}
        contacts.append(contact)

    head_mu = friction if head_friction is None else head_friction

    for r, row in enumerate(layout):
        for name, x0, x1 in row:
            if r == 0:
                pair(f"{name}.bottom", "base.top")
            else:
                for below, b0, b1 in layout[r - 1]:
                    if min(x1, b1) - max(x0, b0) > 1e-9:
                        pair(f"{name}.bottom", f"{below}.top")
    if abutments:
        top = rows * height
        for side, x0, x1 in (("left", -0.1, 0.0), ("right", width, width + 0.1)):
            bodies.append({"name": f"abutment_{side}", "material": {"E": E_base, "nu": nu_base},
                           "mesh": {"block": {"corners": [[x0, 0], [x1, 0], [x1, top], [x0, top]], "nx": 1,
                                              "ny": rows * max(1, cells // 2)}},
                           "boundary": [{"edge": "bottom", "displacement": {"x": 0, "y": 0}},
                                        {"edge": side, "displacement": {"x": 0}}]})
    if abutments or head_joints:
        for row in layout:
            if abutments:
                pair(f"{row[0][0]}.left", "abutment_left.right", head_mu)
            for (name, _, _), (right, _, _) in zip(row, row[1:]):
                pair(f"{name}.right", f"{right}.left", head_mu)
            if abutments:
                pair(f"{row[-1][0]}.right", "abutment_right.left", head_mu)
    stepped = friction is not None and not collapse
    for name, x0, x1 in layout[-1]:
        boundary = next(b for b in bodies if b["name"] == name)["boundary"]
        boundary.append({"edge": "top", "traction": {"normal": pressure}})
        if collapse:
            # The shear as a live load of the collapse analysis: lambda times the brick's vertical load, so that
            # lambda_c is the shear ratio S the wall holds at most.
            boundary.append({"vertex": "top_left", "force": [pressure * (x1 - x0), 0], "live": True})
        elif stepped:
            boundary[-1]["history"] = [1, 1]
            # The shear: S times the brick's vertical load (pressure x its length), growing in step 2.
            boundary.append({"vertex": "top_left", "force": [shear * pressure * (x1 - x0), 0], "history": [0, 1]})

    kind = "_abutments" if abutments else "_head_joints" if head_joints else ""
    name = f"brick_wall_{rows}x{bricks}{kind}" + (f"_mu{friction:g}_shear{shear:g}" if stepped else "")
    if collapse:
        name = f"brick_wall_{rows}x{bricks}{kind}_mu{friction:g}_collapse"
    job = {"name": name, "version": 1, "model": {"plane": "strain"}, "bodies": bodies, "contacts": contacts,
           "solver": {"method": "interface_newton", "enforcement": "exact"}}
    if stepped:
        job["loading"] = {"factors": [1, 1]}
    if collapse:
        job["collapse"] = {}
    return job


def main():
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--rows", type=int, default=8)
    p.add_argument("--bricks", type=int, default=8, help="full bricks per row")
    p.add_argument("--cells", type=int, default=4, help="elements along a full brick (half as many across)")
    p.add_argument("--brick-height", type=float, default=0.07,
                   help="a brick's height (its length is 0.24): 0.12 for stones of 2:1")
    joints = p.add_mutually_exclusive_group()
    joints.add_argument("--abutments", action="store_true",
                        help="no dowels: abutments and head-joint contacts hold the bricks sideways")
    joints.add_argument("--head-joints", action="store_true",
                        help="head-joint contacts between the bricks of a course, the ends of the courses free")
    p.add_argument("--friction", type=float, metavar="MU",
                   help="Coulomb friction MU on every joint, no dowels; precompression, then shear (two steps)")
    p.add_argument("--shear", type=float, default=0.0, metavar="S",
                   help="with --friction: the horizontal load on each top brick in step 2, as a share of its vertical load")
    p.add_argument("--head-friction", type=float, metavar="MU",
                   help="with --friction: the head joints' coefficient (default MU; 0: frictionless head joints)")
    p.add_argument("--collapse", action="store_true",
                   help="with --friction: a collapse analysis instead of the shear S: the precompression dead, the "
                        "shear live (lambda times each top brick's vertical load), lambda raised to its limit")
    p.add_argument("-o", "--output", default="-")
    a = p.parse_args()
    if a.rows < 1 or a.bricks < 1 or a.cells < 2:
        p.error("rows and bricks must be >= 1, cells >= 2")
    if a.friction is not None and not a.friction >= 0:
        p.error("--friction must be >= 0")
    if a.friction is None and a.shear:
        p.error("--shear needs --friction (a frictionless wall without dowels cannot carry a shear)")
    if a.collapse and (a.friction is None or a.shear):
        p.error("--collapse needs --friction and no --shear (the analysis finds the largest shear)")
    if a.friction is None and a.head_friction is not None:
        p.error("--head-friction needs --friction")
    if a.head_friction is not None and not a.head_friction >= 0:
        p.error("--head-friction must be >= 0")
    if a.friction is None and a.head_joints:
        p.error("--head-joints needs --friction or --abutments: frictionless courses with free ends are not held sideways")
    if a.head_joints and a.cells < 4:
        # A half brick of one element rests on its bed joint by one multiplier: its other bed node is a crosspoint
        # (three bodies meet there; docs/algorithm.md, "Crosspoints with friction"), whose multiplier is dropped, and
        # one multiplier carries a uniform pressure only, no moment. Sheared, it turns away from its head joint and
        # nothing holds it: every solver fails, the monolithic reference included (docs/friction.md, "Limits").
        p.error(f"--head-joints needs --cells 4 or more (got {a.cells}): a half brick of one element rests on a "
                "single contact multiplier, which cannot hold the moment of a shear")
    if not a.brick_height > 0:
        p.error("--brick-height must be > 0")
    job = wall(a.rows, a.bricks, a.cells, height=a.brick_height, abutments=a.abutments, head_joints=a.head_joints, friction=a.friction,
               shear=a.shear, head_friction=a.head_friction, collapse=a.collapse)
    text = json.dumps(job, indent=1) + "\n"
    if a.output == "-":
        sys.stdout.write(text)
    else:
        with open(a.output, "w") as f:
            f.write(text)
        print(f"{a.output}: {len(job['bodies'])} bodies, {len(job['contacts'])} contact pairs", file=sys.stderr)


if __name__ == "__main__":
    main()
