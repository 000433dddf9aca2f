"""The integrator of a structure with dry friction that holds (terms of the ``stick`` kind).

A structure with stick terms has two sets of equations, switched per particle at events:

``stuck``    w = 0 held exactly (z' = 0, z'' = 0; other states move on), the friction
             supplying the force f_need that every other force leaves on the mass
             (``rhs``'s second output: drive - springs - the other screw forces at w = 0);
``sliding``  in the direction s = +-1: M z'' = f_need(w) - s F(s w), F the stick terms'
             summed magnitude (Coulomb's level, a Stribeck excess).

After Leine and Nijmeijer's switch model (Leine, van Campen, van de Vrande 1998, "Stick-slip
vibrations induced by alternate friction models", Nonlinear Dyn. 16:41-54), with the
band replaced by the exact condition: stuck while |f_need| <= F_s (the summed holding levels,
``static``), sliding otherwise. Each sub-step is one RK4 step of the current equations (the
sliding direction held fixed, so the law is smooth inside the step) followed by the events'
test at its end:

- stuck, |f_need| > F_s at the end: breakaway. f_need is linear within the step when it
  depends on the input alone (the input is linear within a sample, z is held), so the
  breakaway instant is the linear interpolation of f_need between the step's ends, exact then;
  the step is redone to that instant and continued sliding in the direction of f_need;
- sliding in s, s z' <= 0 at the end: the velocity crossed zero. The instant is the root of
  the cubic Hermite interpolant of z' through (z', z'') at both ends (error O(h^4));
  the step is redone to it, z' set to 0, and the contact sticks if |f_need| <= F_s there,
  or slides on in the direction of f_need (a reversal without a stop).

So the trajectory, and a likelihood built on it, changes continuously with the parameters:
an event moves with them instead of snapping to the step's grid. A sub-step is cut at its
events into pieces, at most its refinement (below) plus 2 ``MAX_EVENTS`` of them, the last
integrated without a test. A velocity that dips through zero and back within one step (its
sign the same at both ends) is not seen: the step's length bounds such a dip. While sliding
slower than a stick term's transition speed (a Stribeck decay's few Stribeck velocities,
``Term.transition``) the pieces are cut to the law's slope there. The right-hand side's
value at the end of each step is the next step's first stage (first same as last), so a
sub-step costs four evaluations as RK4 does. Particles are integrated one at a time (the
events branch); ``benchmarks/bench_sticking.py`` prints the cost against the smooth law.

Limits: no ``coupling`` term (a dead zone would make the stuck condition one on two
velocities) and no ``displacement_update`` state (advanced along the screw's path, which the
stuck equations do not move) in the same structure: ``stick_source`` refuses them.
"""

from __future__ import annotations

import numba as nb

#: Events located per sub-step at most.
MAX_EVENTS = 4
#: Largest (a stick term's slope below its transition speed / M) x piece: the sub-step is cut
#: into pieces that short while sliding that slowly (``simulate.RATE_H``'s value).
TRANSITION_RATE_H = 0.5
#: Illinois iterations on the Hermite cubic for the instant z' crosses zero (h / 2^30 at worst
#: for bisection; the Illinois method converges superlinearly).
CROSSING_ITERATIONS = 30


def has_stick(terms) -> bool:
    """Whether a structure (its Term objects) holds a ``stick`` term."""
    return any(t.kind == "stick" for t in terms)


@nb.njit(error_model="numpy", cache=True)
def breakaway(f0, f1, level):
    """Share of a step (0-1) at which a force going linearly from f0 to f1 (N) reaches the
    level +-``level`` on f1's side; 0 where it started beyond it."""
    target = level if f1 > 0.0 else -level
    if abs(f0) > level or f1 == f0:
        return 0.0
    return min(max((target - f0) / (f1 - f0), 0.0), 1.0)


@nb.njit(error_model="numpy", cache=True)
def _hermite(v0, m0, v1, m1, s):
    s2 = s * s
    s3 = s2 * s
    return ((2.0 * s3 - 3.0 * s2 + 1.0) * v0 + (s3 - 2.0 * s2 + s) * m0
            + (-2.0 * s3 + 3.0 * s2) * v1 + (s3 - s2) * m1)


@nb.njit(error_model="numpy", cache=True)
def crossing(v0, m0, v1, m1):
    """Share of a step (0-1) at which the cubic Hermite interpolant through v0, v1 (m/s) with
    slopes m0, m1 (m/s per step) crosses zero, v0 v1 <= 0 (Illinois' regula falsi)."""
    if v0 == 0.0:
        return 0.0
    if v1 == 0.0:
        return 1.0
    a, b, fa, fb = 0.0, 1.0, v0, v1
    side = 0
    x = 1.0
    for _ in range(CROSSING_ITERATIONS):
        x = (a * fb - b * fa) / (fb - fa)
        fx = _hermite(v0, m0, v1, m1, x)
        if fx == 0.0 or b - a < 1e-14:
            return x
        if (fx > 0.0) == (fb > 0.0):
            b, fb = x, fx
            if side == -1:
                fa *= 0.5
            side = -1
        else:
            a, fa = x, fx
            if side == 1:
                fb *= 0.5
            side = 1
    return x


# --------------------------------------------------------------------------- the source


def _excluded(terms) -> list[str]:
    """The terms a structure with stick terms cannot hold (module docstring's limits)."""
    return [t.name for t in terms if t.kind == "coupling" or t.displacement_update is not None]


def compatible(terms) -> bool:
    """Whether the integrator takes a structure (its Term objects): no stick term, or none
    of the terms it cannot hold beside one."""
    return not has_stick(terms) or not _excluded(terms)


def _check(terms) -> None:
    bad = _excluded(terms)
    if bad:
        raise ValueError(f"a structure with dry friction that sticks cannot hold {bad}: a "
                         "coupling or a state advanced along the screw's path "
                         "(harvester.model.stick's limits)")


def _rk4_source(states: list[str], params: list[str]) -> str:
    """``rk4``: one RK4 step of h from the states y with first stage k (rhs's outputs), the
    input u0 + du t, the sliding direction _s held."""
    n = len(states)
    ys = [f"y{j}" for j in range(n)]
    ks = [f"k{j}" for j in range(n + 2)]
    ps = ", ".join(params)

    def stage(name, src, scale, t):
        st = ", ".join(f"y{j} + {scale} * {src}[{j + 2}]" if src != "k" else
                       f"y{j} + {scale} * k{j + 2}" for j in range(n))
        return f"    {name} = rhs(u0 + {t} * du, _s, {st}, {ps})"

    out = ", ".join(f"y{j} + h / 6.0 * (k{j + 2} + 2.0 * b[{j + 2}] + 2.0 * c[{j + 2}] + "
                    f"d[{j + 2}])" for j in range(n))
    return "\n".join([
        f"def rk4(u0, du, h, _s, {', '.join(ys)}, {', '.join(ks)}, {ps}):",
        stage("b", "k", "0.5 * h", "0.5 * h"), stage("c", "b", "0.5 * h", "0.5 * h"),
        stage("d", "c", "h", "h"), f"    return ({out},)"])


def _step_source(states: list[str], params: list[str], statics: str,
                 transitions: list[str]) -> str:
    """``stick_piece``: one RK4 step of at most h, cut at its first event (module
    docstring); returns (time advanced, direction, states, rhs there). ``stick_step``: one
    sub-step of a particle from ua to uc (input at its ends) in pieces: whole while stuck or
    sliding fast, 1/fine of the sub-step while sliding below the stick terms' (summed)
    transition speeds, where their laws change at the summed slope (``Term.transition``)."""
    n = len(states)
    ys = ", ".join(f"y{j}" for j in range(n))
    ns = ", ".join(f"n{j}" for j in range(n))
    ks = ", ".join(f"k{j}" for j in range(n + 2))
    ps = ", ".join(params)
    names = [f"_tr{j}" for j in range(len(transitions))]
    speed = " + ".join(f"{t}[0]" for t in names) or "0.0"
    slope = " + ".join(f"{t}[1]" for t in names) or "0.0"
    calls = "\n".join(f"    {t} = {call}" for t, call in zip(names, transitions))
    return f"""def stick_piece(u0, du, h, test, _s, {ys}, {ks}, {ps}):
    level = {statics}
    {ns}, = rk4(u0, du, h, _s, {ys}, {ks}, {ps})
    e = rhs(u0 + du * h, _s, {ns}, {ps})
    theta = 1.0
    if test:
        if _s == 0.0:
            if abs(e[1]) > level:
                theta = breakaway(k1, e[1], level)
        elif _s * n1 <= 0.0:
            theta = crossing(y1, k0 * h, n1, e[0] * h)
    if theta >= 1.0:
        return (h, _s, {ns}) + e
    tau = theta * h
    if tau > 0.0:
        {ys}, = rk4(u0, du, tau, _s, {ys}, {ks}, {ps})
    y1 = 0.0
    g = rhs(u0 + du * tau, 0.0, {ys}, {ps})
    if _s != 0.0 and abs(g[1]) <= level:
        return (tau, 0.0, {ys}) + g
    _s = 1.0 if g[1] > 0.0 else -1.0
    return (tau, _s, {ys}) + rhs(u0 + du * tau, _s, {ys}, {ps})


{{jit}})
def stick_step(ua, uc, h, _s, {ys}, {ks}, {ps}):
    du = (uc - ua) / h
{calls}
    slow = {speed}
    fine = max(1.0, np.ceil(({slope}) / abs(M) * h / TRANSITION_RATE_H))
    pieces = int(fine) + 2 * MAX_EVENTS
    t = 0.0
    for it in range(pieces):
        rem = h - t
        if rem <= 1e-12 * h:
            break
        test = it < pieces - 1
        hp = rem
        if test and _s != 0.0 and _s * y1 < slow:
            hp = min(rem, h / fine)
        adv, _s, {ys}, {ks} = stick_piece(ua + du * t, du, hp, test, _s, {ys}, {ks}, {ps})
        t += adv
    return (_s, {ys}, {ks})"""


def _integrate_source(states: list[str], params: list[str], driver: str, d: dict) -> str:
    """``integrate``: the sub-steps of every particle of a block in turn (``stick_step``),
    the direction and the right-hand side at the step's end carried between steps, z, z',
    z'' written at the samples, a particle beyond ``BLOW_UP`` flagged and reset (``d``: the
    driver's pieces of source, ``codegen``'s)."""
    n = len(states)
    load = "\n".join(f"    p_{p} = P[{j}]" for j, p in enumerate(params))
    init = "\n".join(f"    x{j} = np.zeros(C)" for j in range(n))
    carry = "\n".join(f"    kc{j} = np.zeros(C)" for j in range(n + 2))
    pc = ", ".join(f"p_{p}[c]" for p in params)
    xs = ", ".join(f"x{j}[c]" for j in range(n))
    qs = ", ".join(f"kc{j}[c]" for j in range(n + 2))
    zeros = ", ".join("0.0" for _ in range(n))
    check = " and ".join(f"abs(x{j}[c]) < BLOW_UP" for j in range(n))
    reset = "; ".join(f"x{j}[c] = 0.0" for j in range(n))
    if driver == "servo":
        first = ""
        fresh = (f"                if s == 0:\n"
                 f"                    {qs} = rhs(uu[c], sm[c], {xs}, {pc})\n")
        ends = "uu[c], uu[c]"
    else:
        first = f"    for c in range(C):\n        {qs} = rhs(u[0], 0.0, {zeros}, {pc})\n"
        fresh, ends = "", "ua, uc"
    return f"""{d["head"]}
    C = P.shape[1]
{load}
{init}
{carry}
    sm = np.zeros(C)
{d["prologue"]}
{first}    scratch = np.empty(C)
    for i in range(n):
{d["sample"]}{d["writes"]}        {d["interval"]}
        {d["slope"]}
        for s in range(1 if last else n_sub):
{d["inputs"]}            row = acc_row if s == 0 else scratch
            for c in range(C):
{fresh}                row[c] = kc0[c]
                if not last:
                    sm[c], {xs}, {qs} = stick_step({ends}, h, sm[c], {xs}, {qs}, {pc})
        if last:
            break
        for c in range(C):
            if not ({check}):
                ok[c] = False
                {reset}; sm[c] = 0.0
"""


def stick_source(terms, driver: str, pieces: dict, names: tuple[list[str], list[str]],
                 jit: str) -> list[str]:
    """The generated functions after ``rhs`` of a structure with stick terms, given by
    ``codegen.source`` (which this module does not import): the ``driver``'s name and its
    pieces of source, the structure's (parameter, state) ``names``, and ``jit`` the
    decorator's opening."""
    _check(terms)
    params, states = names
    statics = " + ".join(f"_static{i}({', '.join(t.parameter_names)})"
                         for i, t in enumerate(terms) if t.kind == "stick")
    transitions = [f"_transition{i}({', '.join(t.parameter_names)})"
                   for i, t in enumerate(terms) if t.transition is not None]
    step = _step_source(states, params, statics, transitions).replace("{jit}", jit)
    return [f'{jit}, inline="always")', _rk4_source(states, params), "", "",
            f'{jit}, inline="always")', step, "", "",
            f"{jit}, nogil=True)", _integrate_source(states, params, driver, pieces)]
