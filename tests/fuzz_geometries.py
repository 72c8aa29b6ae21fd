"""Small valid jobs in every relative position, as a hostile or careless user would write them: one- and
few-element blocks side by side, stacked, apart, overlapping, nested, touching at a corner, with pairs named
right and mistyped (an edge that faces the other body or one that does not, slave and master swapped), supports
that hold a body or leave it floating, with and without friction. Every job is valid JSON of the job format;
many are models the solver must refuse or fail, and none may crash it.

    from fuzz_geometries import jobs
    for job in jobs(count=40, seed=1): ...

Deterministic for a seed (random.Random), so a failure names a job that can be made again."""
import random

EDGES = ("bottom", "right", "top", "left")

# Where body 1 stands against body 0 (a unit square at the origin, scaled): its lower-left corner, in units of
# body 0's size, and the placements' names (a failing job's name says which it was).
PLACEMENTS = {
    "on_top": (0.0, 1.0), "beside": (1.0, 0.0), "apart_up": (0.0, 1.5), "apart_side": (1.7, 0.0),
    "overlap_up": (0.0, 0.9), "overlap_side": (0.95, 0.0), "corner": (1.0, 1.0), "diagonal_apart": (1.5, 1.5),
    "nested": (0.25, 0.25), "shifted_on_top": (0.6, 1.0), "below": (0.0, -1.0), "far": (7.0, -3.0),
}


def block(name, x, y, w, h, nx, ny, boundary):
    return {"name": name, "material": {"E": 1.0, "nu": 0.3},
            "mesh": {"block": {"corners": [[x, y], [x + w, y], [x + w, y + h], [x, y + h]], "nx": nx, "ny": ny}},
            "boundary": boundary}


def supports(rng, at_rest):
    """A body's conditions: clamped at an edge, pushed by a prescribed displacement or a force, or nothing."""
    kind = rng.choice(["clamped", "clamped", "pushed", "pushed", "loaded", "roller", "free"] if not at_rest
                      else ["clamped"])
    edge = rng.choice(EDGES)
    if kind == "clamped":
        return [{"edge": edge, "displacement": {"x": 0, "y": 0}}]
    if kind == "pushed":
        return [{"edge": edge, "displacement": {"x": round(rng.uniform(-0.02, 0.02), 4),
                                                 "y": round(rng.uniform(-0.02, 0.02), 4)}}]
    if kind == "loaded":
        return [{"edge": edge, "force": [round(rng.uniform(-1, 1), 3), round(rng.uniform(-1, 1), 3)]}]
    if kind == "roller":
        return [{"edge": edge, "displacement": {rng.choice("xy"): 0}},
                {"edge": rng.choice(EDGES), "force": [0, -0.1]}]
    return []


def pair(rng, bodies):
    """A contact pair between two different bodies: the edges that meet where there are such, or any edge."""
    s, m = rng.sample(range(len(bodies)), 2)
    return {"slave": f"{bodies[s]['name']}.{rng.choice(EDGES)}", "master": f"{bodies[m]['name']}.{rng.choice(EDGES)}"}


def sensible_pair(placement):
    """The pair a careful user would write for the placement (body 1 against body 0), where there is one."""
    return {"on_top": ("b1.bottom", "b0.top"), "shifted_on_top": ("b1.bottom", "b0.top"),
            "overlap_up": ("b1.bottom", "b0.top"), "apart_up": ("b1.bottom", "b0.top"),
            "beside": ("b1.left", "b0.right"), "overlap_side": ("b1.left", "b0.right"),
            "apart_side": ("b1.left", "b0.right"), "below": ("b1.top", "b0.bottom")}.get(placement)


def job(rng, index):
    placement = rng.choice(sorted(PLACEMENTS))
    ox, oy = PLACEMENTS[placement]
    size = rng.choice([0.5, 1.0, 2.0])
    scale1 = 0.5 if placement == "nested" else rng.choice([0.5, 1.0, 1.5])
    bodies = [block("b0", 0, 0, size, size, rng.choice([1, 1, 2, 3]), rng.choice([1, 1, 2]), supports(rng, True)),
              block("b1", ox * size, oy * size, scale1 * size, scale1 * size, rng.choice([1, 1, 2, 3]),
                    rng.choice([1, 2]), supports(rng, False))]
    if rng.random() < 0.25:  # a third body, on top of the second or beside the first
        bodies.append(block("b2", rng.choice([0, 1]) * size, 2 * size, size, size, rng.choice([1, 2]), 1,
                            supports(rng, False)))
    contacts = []
    sensible = sensible_pair(placement)
    if sensible and rng.random() < 0.7:
        s, m = sensible
        if rng.random() < 0.3:
            s, m = m, s  # slave and master swapped: as valid
        contacts.append({"slave": s, "master": m})
    while not contacts or (len(contacts) < 3 and rng.random() < 0.25):
        p = pair(rng, bodies)
        if all({p["slave"], p["master"]} != {c["slave"], c["master"]} for c in contacts):
            contacts.append(p)
    if rng.random() < 0.3:
        for c in contacts:
            c["friction"] = {"coefficient": rng.choice([0.1, 0.5, 1.0])}
    out = {"name": f"fuzz-{index}-{placement}", "bodies": bodies, "contacts": contacts,
           "solver": {"max_iterations": 200}}
    if rng.random() < 0.2:
        out["loading"] = {"steps": 2}
    return out


def jobs(count, seed=1):
    rng = random.Random(seed)
    return [job(rng, i) for i in range(count)]
