"""Jobs of the limit state with their classical answers, shared by the tests and bench/bench_collapse.py: a column of
blocks (column()), and a semicircular arch of N voussoirs (straight intrados and extrados chords, radial joints) under its own weight:
the job, and its limit thickness by the classical thrust-line argument (Heyman; Milankovitch's problem), computed
here independently of the solver.

The thrust line: by symmetry (N even: the crown is a joint) the crown joint carries a horizontal thrust H at a height
y_c on it. Walking from the crown to the left springing, the force through joint j is the crown's thrust plus the
weights of the voussoirs between, F_j = (-H, -W_j), with the moment M_j = H y_c - sum w_i x_i about the origin; its
line of action meets the joint's radial line at radius r_j = M_j / (H sin(phi_j) - W_j cos(phi_j)). The arch stands
(rigid voussoirs, no tension, no sliding) iff some H > 0 and y_c put every r_j within the joint, R - t/2 <= r_j <=
R + t/2 (y_c itself within the crown joint). For fixed H each bound is linear in y_c, so the admissible y_c form an
interval; in u = 1 / H every bound is linear, so the interval's width is concave in u and its maximum over u
(golden-section search) says whether any H admits a line. The limit thickness is the smallest t that admits a thrust line, by bisection."""
import math


def voussoirs(n, t, radius=1.0):
    """The n voussoirs' corners, each [inner-left, inner-right, outer-right, outer-left] (counterclockwise), from the
    left springing (phi = pi) to the right (phi = 0)."""
    r_in, r_out = radius - t / 2, radius + t / 2
    out = []
    for i in range(n):
        a, b = math.pi - i * math.pi / n, math.pi - (i + 1) * math.pi / n
        out.append([(r_in * math.cos(a), r_in * math.sin(a)), (r_in * math.cos(b), r_in * math.sin(b)),
                    (r_out * math.cos(b), r_out * math.sin(b)), (r_out * math.cos(a), r_out * math.sin(a))])
    return out


def area_centroid(quad):
    """A polygon's area and centroid (shoelace)."""
    a = cx = cy = 0.0
    for (x0, y0), (x1, y1) in zip(quad, quad[1:] + quad[:1]):
        c = x0 * y1 - x1 * y0
        a += c
        cx += (x0 + x1) * c
        cy += (y0 + y1) * c
    return a / 2, (cx / (3 * a), cy / (3 * a))


def admits_thrust_line(n, t, radius=1.0, with_line=False):
    """Whether a thrust line fits within the arch of thickness t (n even), and the largest ratio of tangential to
    normal force over the joints of the one found (what friction must carry); with_line: instead of the ratio, the
    line itself, (phi, r) where it crosses each joint of the left half, from the crown to the springing."""
    assert n % 2 == 0, "the crown must be a joint"
    quads = voussoirs(n, t, radius)
    half = quads[: n // 2]  # the left half, springing first
    # Joints of the left half from the crown (phi = pi / 2) to the springing (phi = pi), and the weights between.
    joints = []
    W = S = 0.0
    for k in range(n // 2, 0, -1):  # voussoir k - 1 lies between joint phi_k and phi_{k-1}
        area, (x, _) = area_centroid(half[k - 1])
        W += area
        S += area * x
        phi = math.pi - (k - 1) * math.pi / n
        joints.append((phi, W, S))
    r_lo, r_hi = radius - t / 2, radius + t / 2
    total = W

    def interval(H):
        lo, hi = r_lo, r_hi  # y_c on the crown joint
        for phi, Wj, Sj in joints:
            d = H * math.sin(phi) - Wj * math.cos(phi)
            if d <= 0:
                return None
            # r = (H y_c - S) / d in [r_lo, r_hi]  <=>  y_c in [(r_lo d + S) / H, (r_hi d + S) / H]
            lo, hi = max(lo, (r_lo * d + Sj) / H), min(hi, (r_hi * d + Sj) / H)
        return (lo, hi) if lo <= hi else None

    # In u = 1 / H every bound is a + b u: the slack min(upper) - max(lower) is concave in u, and its maximum
    # (golden-section search) says whether any thrust H admits a line.
    def slack(u):
        iv = interval(1.0 / u)
        if iv:
            return iv[1] - iv[0]
        lo, hi = r_lo, r_hi
        for phi, Wj, Sj in joints:
            d = math.sin(phi) - Wj * math.cos(phi) * u  # d / H
            lo, hi = max(lo, r_lo * d + Sj * u), min(hi, r_hi * d + Sj * u)
        return hi - lo
    a, b = 1e-9 / total, 100.0 / total
    g = (math.sqrt(5) - 1) / 2
    for _ in range(200):
        c, d = b - g * (b - a), a + g * (b - a)
        if slack(c) >= slack(d):
            b = d
        else:
            a = c
    u = (a + b) / 2
    if slack(u) < 0:
        return False, None
    H = 1.0 / u
    lo, hi = interval(H)
    if with_line:
        y_c = (lo + hi) / 2
        return True, [(math.pi / 2, y_c)] + [(phi, (H * y_c - Sj) / (H * math.sin(phi) - Wj * math.cos(phi)))
                                             for phi, Wj, Sj in joints]
    y_c = (lo + hi) / 2
    ratio = 0.0
    for phi, Wj, Sj in joints:
        F = (-H, -Wj)
        normal = (-math.sin(phi), math.cos(phi))  # along the arch (the joint's normal)
        fn = F[0] * normal[0] + F[1] * normal[1]
        ft = F[0] * math.cos(phi) + F[1] * math.sin(phi)
        ratio = max(ratio, abs(ft) / abs(fn))
    return True, ratio


def limit_thickness(n, radius=1.0, tolerance=1e-7):
    """The smallest t / R whose arch admits a thrust line (bisection)."""
    lo, hi = 0.01 * radius, 0.5 * radius
    assert admits_thrust_line(n, hi, radius)[0] and not admits_thrust_line(n, lo, radius)[0]
    while hi - lo > tolerance * radius:
        mid = (lo + hi) / 2
        if admits_thrust_line(n, mid, radius)[0]:
            hi = mid
        else:
            lo = mid
    return hi / radius


def arch_job(n, t, radius=1.0, mu=0.9, cells=(2, 4)):
    """The arch as a job: n voussoirs (density 1, gravity 10) between two clamped abutments, Coulomb mu on every
    joint (voussoir i's right edge the slave of voussoir i + 1's left edge, the springings the voussoirs' ends on
    the abutments' tops)."""
    r_in, r_out = radius - t / 2, radius + t / 2
    bodies, contacts = [], []
    material = {"E": 1e6, "nu": 0.2, "density": 1.0}
    for i, q in enumerate(voussoirs(n, t, radius)):
        bodies.append({"name": f"v{i}", "material": material,
                       "mesh": {"block": {"corners": [list(p) for p in q], "nx": cells[0], "ny": cells[1]}}})
    for side, x0, x1 in (("left", -r_out - 0.1, -r_in + 0.1), ("right", r_in - 0.1, r_out + 0.1)):
        bodies.append({"name": f"abutment_{side}", "material": {"E": 1e6, "nu": 0.2},
                       "mesh": {"block": {"corners": [[x0, -0.2], [x1, -0.2], [x1, 0], [x0, 0]], "nx": 4, "ny": 2}},
                       "boundary": [{"edge": "bottom", "displacement": {"x": 0, "y": 0}}]})
    friction = {"coefficient": mu}
    contacts.append({"slave": "v0.left", "master": "abutment_left.top", "friction": friction})
    for i in range(n - 1):
        contacts.append({"slave": f"v{i}.right", "master": f"v{i + 1}.left", "friction": friction})
    contacts.append({"slave": f"v{n - 1}.right", "master": "abutment_right.top", "friction": friction})
    return {"name": f"arch_{n}_t{t:.5f}", "model": {"gravity": [0, -10]}, "bodies": bodies, "contacts": contacts}


def hinges_at_limit(n, radius=1.0):
    """The joints where the thrust line of the limit arch touches its edge, in the left half from the crown: (phi,
    "intrados" or "extrados"). The classical five-hinge mechanism is these and their mirror images."""
    t = limit_thickness(n, radius)
    _, line = admits_thrust_line(n, t, radius, with_line=True)
    r_in, r_out = radius - t / 2, radius + t / 2
    out = []
    for phi, r in line:
        if abs(r - r_in) < 1e-4 * radius:
            out.append((phi, "intrados"))
        elif abs(r - r_out) < 1e-4 * radius:
            out.append((phi, "extrados"))
    return out


def column(n=3, push=10.0, mu=0.8, nx=4):
    """n blocks 1 x 1 stacked on a clamped ground (density 1, gravity [0, -10] dead), Coulomb mu on every joint, a
    horizontal body force `push` per volume live: the column overturns about the base's toe at lambda_c = 1 / n
    (b / (n h)) while that is below mu."""
    def block(name, y0):
        return {"name": name, "material": {"E": 1e5, "nu": 0.2, "density": 1.0},
                "mesh": {"block": {"corners": [[0, y0], [1, y0], [1, y0 + 1], [0, y0 + 1]], "nx": nx, "ny": nx}},
                "body_force": {"value": [push, 0], "live": True}}
    ground = {"name": "ground", "material": {"E": 1e5, "nu": 0.2},
              "mesh": {"block": {"corners": [[-1, -1], [2, -1], [2, 0], [-1, 0]], "nx": 3 * nx, "ny": 3}},
              "boundary": [{"edge": "bottom", "displacement": {"x": 0, "y": 0}}]}
    return {"name": "column", "model": {"gravity": [0, -10]},
            "bodies": [ground] + [block(f"b{i + 1}", i) for i in range(n)],
            "contacts": [{"slave": f"b{i + 1}.bottom", "master": "ground.top" if i == 0 else f"b{i}.top",
                          "friction": {"coefficient": mu}} for i in range(n)],
            "collapse": {}}

