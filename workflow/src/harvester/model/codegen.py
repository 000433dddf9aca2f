"""Compiled kernels per model structure: the integrator, generated once and cached on disk.

A structure (a tuple of term names) and a driver (how the input enters) get one generated
Python module holding

``rhs``        the right-hand side of eq. (1) with the structure's terms, written as straight
               code: each term's force law (``model/terms/<name>.py``) is compiled into it, so
               no term is chosen while integrating;
``integrate``  classical RK4 over a block of particles that share a sub-step count, with the
               particles innermost (struct of arrays) so that the compiler vectorises the
               loop over them (4 doubles per AVX2 instruction); a rate-independent state
               (a term's ``displacement_update``, the Dahl friction) is advanced exactly
               along each stage's screw displacement instead;

Inlining. ``rhs``, every term's law and ``turning_point`` are inlined into ``integrate`` in
Numba's IR (``inline="always"``), and the elementary functions of ``fastmath`` into them,
so that the loop over particles holds no call: LLVM's own inliner, left to choose, kept the
laws of two terms (or one law with a ``fastmath`` exp or tanh) as calls once the loop grew,
and a loop with a call stays scalar. Measured on 31 kernels (the tanh baseline with one
term, and with hysteresis or a mode and one more): 13 were scalar before, none after, with
the same numbers to the bit; the LuGre record's tanh + hysteresis + mode took 9.75 ms per
particle, 2.54 after. The price is compilation, nearly all of it Numba's inlining and
typing (LLVM about 1 s of a kernel's 5-9 s): 65 s for the 31 before, 175 s after, once per
structure (the disk cache keeps it). ``benchmarks/bench_simulator.py`` prints each kernel's
speed-up from its vector lanes.

``integrate`` releases the GIL: ``harvester.model.simulate`` runs the blocks of a population
in a pool of threads, each block followed at once by its acquisition (compiled once for every
structure in ``harvester.model.acquisition``), so a new structure compiles only ``rhs`` and
``integrate`` (about a second).

Drivers: ``base`` (input the base acceleration y'', drive -m y''; for a structure with a
``ground`` term the input is complex, y'' + 1j y', so that the base velocity is interpolated
with it through every integrator unchanged), ``force`` (a force on the mass, base fixed),
``servo`` (a digital position loop computes the force at every sample from
the simulated position, held over the sample: the EMPS drive).

The module's source is written to a cache directory (``HARVESTER_CACHE`` or
``~/.cache/harvester/kernels``) under a name that hashes the generated text and the source of
every file it depends on (the term files, ``fastmath``, ``acquisition`` and this generator),
and imported from there, so that Numba's own cache (``cache=True``) keeps the machine code
between processes and a change of any term recompiles what uses it.
"""

from __future__ import annotations

import hashlib
import importlib.util
import os
import sys
import tempfile
import threading
from pathlib import Path
from types import ModuleType

import numba as nb

from harvester.model.stick import has_stick
from harvester.model.stick import stick_source as _stick_source
from harvester.model.terms import Term, term

#: States beyond this magnitude count as a failed (unstable) simulation.
BLOW_UP = 1.0e6
DRIVERS = ("base", "force", "servo")

_compiled: dict[tuple[str, str], object] = {}
_modules: dict[tuple[tuple[str, ...], str], ModuleType] = {}
_lock = threading.Lock()


def compiled(term_name: str, function: str):
    """A term's law (``force``, ``state_rates``, ``masses``, ``displacement_update``),
    compiled to be inlined where it is called (module docstring)."""
    key = (term_name, function)
    if key not in _compiled:
        fn = getattr(term(term_name), function)
        _compiled[key] = nb.njit(error_model="numpy", cache=True, inline="always")(fn)
    return _compiled[key]


# --------------------------------------------------------------------------- the source


@nb.njit(error_model="numpy", cache=True, inline="always")
def turning_point(w0, w1, dx, h):
    """Displacement (m) at which the motion over a step reverses, on the cubic Hermite path
    through (0, 0, w0) and (h, dx, w1); dx where it does not reverse (w0 w1 >= 0)."""
    if w0 * w1 >= 0.0:
        return dx
    g = dx / h
    # x'(s h) = a s^2 + b s + w0, s in (0, 1), one root there since w0 w1 < 0
    a = 3.0 * w0 - 6.0 * g + 3.0 * w1
    b = -4.0 * w0 + 6.0 * g - 2.0 * w1
    if abs(a) < 1e-12 * (abs(b) + abs(w0)):
        s = -w0 / b
    else:
        disc = max(b * b - 4.0 * a * w0, 0.0)
        q = -0.5 * (b + (disc ** 0.5 if b >= 0.0 else -disc ** 0.5))
        s = q / a
        if not 0.0 <= s <= 1.0:
            s = w0 / q
    s = min(max(s, 0.0), 1.0)
    return (h * (w0 * (s - 2.0 * s * s + s ** 3) + w1 * (s ** 3 - s * s))
            + dx * s * s * (3.0 - 2.0 * s))


def has_ground(terms: tuple[Term, ...]) -> bool:
    """Whether a structure holds a term on the mass's absolute velocity (``ground``)."""
    return any(t.kind == "ground" for t in terms)


def _names(terms: tuple[Term, ...]) -> tuple[list[str], list[str]]:
    """(parameter names, state names) of a structure in layout order."""
    params = ["M", "m", "k", "c_m"] + [p for t in terms for p in t.parameter_names]
    states = ["z", "v"]
    for i, t in enumerate(terms):
        states += [f"_x{i}_{j}" for j in range(t.n_states)]
    return params, states


def _rhs_source(terms: tuple[Term, ...], driver: str) -> str:
    """The right-hand side: (a, d state / dt ...) of one particle."""
    params, states = _names(terms)
    sticks = [i for i, t in enumerate(terms) if t.kind == "stick"]
    mode = "_s, " if sticks else ""
    lines = [f"def rhs(_u, {mode}{', '.join(states)}, {', '.join(params)}):",
             "    _M = M", "    _m = m"]
    state_of = {}
    k = 2
    for i, t in enumerate(terms):
        state_of[i] = states[k:k + t.n_states]
        k += t.n_states
    args = {i: ", ".join(t.parameter_names) for i, t in enumerate(terms)}
    for i, t in enumerate(terms):
        if t.masses is not None:
            lines.append(f"    _M, _m = _masses{i}(_M, _m, {args[i]})")
    if driver == "base" and has_ground(terms):  # _u = y'' + 1j y' (module docstring)
        lines += ["    _drive = -_m * _u.real", "    _yb = _u.real", "    _vb = _u.imag"]
    elif driver == "base":
        lines += ["    _drive = -_m * _u", "    _yb = _u"]
    else:  # the base is fixed: the ground is the base
        lines += ["    _drive = _u", "    _yb = 0.0"] + (["    _vb = 0.0"] if has_ground(terms)
                                                       else [])
    coupling = [i for i, t in enumerate(terms) if t.kind == "coupling"]
    lines.append(f"    _w = v - {state_of[coupling[0]][1]}" if coupling else "    _w = v")
    lines += ["    _f_screw = c_m * _w", "    _f_mass = k * z", "    _f_mode = 0.0"]
    for i, t in enumerate(terms):
        st = "".join(f"{s}, " for s in state_of[i])
        if t.kind == "screw":
            lines.append(f"    _f_screw += _force{i}(_w, {st}{args[i]})")
        elif t.kind == "mass":
            lines.append(f"    _f_mass += _force{i}(z, {args[i]})")
        elif t.kind == "ground":
            lines.append(f"    _f_mass += _force{i}(v + _vb, {args[i]})")
        elif t.kind == "mode":
            lines.append(f"    _f_mode += _force{i}({st}{args[i]})")
    derivs: dict[str, str] = {}
    lines += _acceleration_lines(terms, state_of, args, derivs)
    for i, t in enumerate(terms):
        if t.kind == "screw" and t.n_states:
            out = ", ".join(f"_d{s}" for s in state_of[i])
            lines.append(f"    {out} = _rates{i}(_w, {''.join(f'{s}, ' for s in state_of[i])}"
                         f"{args[i]})")
            derivs.update({s: f"_d{s}" for s in state_of[i]})
        elif t.kind == "mode":
            u0, u1 = state_of[i]
            lines.append(f"    _d{u0}, _d{u1} = _rates{i}({u0}, {u1}, _a, _yb, {args[i]})")
            derivs.update({u0: f"_d{u0}", u1: f"_d{u1}"})
    derivs["z"], derivs["v"] = "v", "_a"
    need = "_f_other, " if sticks else ""
    lines.append(f"    return _a, {need}" + ", ".join(derivs[s] for s in states))
    return "\n".join(lines)


def _acceleration_lines(terms: tuple[Term, ...], state_of: dict, args: dict,
                        derivs: dict[str, str]) -> list[str]:
    """The lines of ``rhs`` that give the mass's acceleration ``_a``: through a coupling (its
    dead zone's states' rates added to ``derivs``), with stick terms (held or sliding in the
    direction ``_s``), or plain eq. (1)."""
    coupling = [i for i, t in enumerate(terms) if t.kind == "coupling"]
    sticks = [i for i, t in enumerate(terms) if t.kind == "stick"]
    lines: list[str] = []
    if coupling:
        i = coupling[0]
        d, dd = state_of[i]
        lines += [f"    _fb = _force{i}({d}, {dd}, _M, _m, {args[i]})",
                  "    _j_eq = max(_M - _m, 1e-6)",
                  "    _a = (_drive - _f_mass - _fb + _f_mode) / _m",
                  f"    _d{dd} = _a - (_fb - _f_screw) / _j_eq"]
        derivs[d], derivs[dd] = dd, f"_d{dd}"
    elif sticks:
        # stuck (_s = 0): w = 0 held, the friction supplies _f_other; sliding in the direction
        # _s = +-1: the stick terms' magnitude at the speed along it
        dry = " + ".join(f"_force{i}(_sp, {args[i]})" for i in sticks)
        lines += ["    _f_other = _drive - _f_screw - _f_mass + _f_mode",
                  "    _sp = max(_s * _w, 0.0)",
                  f"    _a = abs(_s) * (_f_other - _s * ({dry})) / _M"]
    else:
        lines.append("    _a = (_drive - _f_screw - _f_mass + _f_mode) / _M")
    return lines


def _exact_states(terms: tuple[Term, ...]) -> tuple[dict[int, int], str, str]:
    """(state index -> term index) of the states advanced by their term's
    ``displacement_update``; the screw displacement's rate in an rhs result ``{k}`` as a
    template (z', less the coupling's d' where the structure has one); and the screw's
    velocity at the end of the step (the same, from the new states)."""
    exact, k, rate, w_end = {}, 2, "{k}[1]", "x1[c]"
    for i, t in enumerate(terms):
        if t.displacement_update is not None:
            exact[k] = i
        if t.kind == "coupling":  # states d (index k) and d' (index k + 1)
            rate, w_end = f"({{k}}[1] - {{k}}[{k + 1}])", f"(x1[c] - x{k + 1}[c])"
        k += t.n_states
    return exact, rate, w_end


def _step_source(terms: tuple[Term, ...], driver: str) -> str:
    """The body of one RK4 step of particle c (indented for the loop it sits in). A state
    with a ``displacement_update`` is set at each stage, and at the end, to its exact value
    after the screw displacement that the stage assumes (no RK4 of its own rate)."""
    params, states = _names(terms)
    n = len(states)
    p_args = ", ".join(f"p_{p}[c]" for p in params)
    exact, rate, w_end = _exact_states(terms)
    t_args = {i: "".join(f", p_{p}[c]" for p in terms[i].parameter_names)
              for i in set(exact.values())}
    body = [f"y{j} = x{j}[c]" for j in range(n)]
    u = {"a": "ua", "b": "ub", "c": "uc"} if driver != "servo" else \
        {"a": "uu[c]", "b": "uu[c]", "c": "uu[c]"}

    def value(j, k, scale):
        if j in exact:
            dx = f"{scale} * {rate.format(k=f'k{k - 1}')}"
            return f"_update{exact[j]}(y{j}, {dx}{t_args[exact[j]]})"
        return f"y{j} + {scale} * k{k - 1}[{j + 1}]"

    def call(k, inp, scale):
        st = ", ".join(f"y{j}" if scale is None else value(j, k, scale) for j in range(n))
        return f"k{k} = rhs({inp}, {st}, {p_args})"

    body += [call(1, u["a"], None), "row[c] = k1[0]",
             call(2, u["b"], "half"), call(3, u["b"], "half"), call(4, u["c"], "h")]
    for j in range(n):
        if j not in exact:
            body.append(f"x{j}[c] = y{j} + sixth * (k1[{j + 1}] + 2.0 * k2[{j + 1}] + "
                        f"2.0 * k3[{j + 1}] + k4[{j + 1}])")
    if exact:
        dx = " + ".join(f"{w}{rate.format(k=f'k{k}')}" for k, w in
                        ((1, ""), (2, "2.0 * "), (3, "2.0 * "), (4, "")))
        body += [f"dx = sixth * ({dx})",
                 f"turn = turning_point({rate.format(k='k1')}, {w_end}, dx, h)"]
        body += [f"x{j}[c] = _update{i}(_update{i}(y{j}, turn{t_args[i]}), dx - turn"
                 f"{t_args[i]})" for j, i in exact.items()]
    return "\n".join(body)


#: The servo driver's pieces of ``integrate``: the position loop's force at every sample.
#: What every integrator writes at a sample: z and z' where asked, and the row z'' goes to
#: (the sampled and the sticking integrators alike, ``stick.stick_source``).
WRITES = """        if out_z.shape[0] > 0:
            for c in range(C):
                out_z[i, c] = x0[c]
        if out_v.shape[0] > 0:
            for c in range(C):
                out_v[i, c] = x1[c]
        acc_row = out_acc[i] if out_acc.shape[0] > 0 else scratch
        last = i == n - 1
"""

_SERVO = dict(
    head=("def integrate(qg, dist, dt, q0, gtau, kp, kv, n_sub, h, P, out_acc, out_z, "
          "out_v, out_f, ok):"),
    prologue=("    n = qg.shape[0]\n    uu = np.empty(C)\n    q1 = np.empty(C)\n"
              "    q2 = np.empty(C)\n    for c in range(C):\n"
              "        q1[c] = q0\n        q2[c] = q0\n        x0[c] = q0"),
    sample=("        for c in range(C):\n"
            "            q = x0[c]\n"
            "            uu[c] = gtau * (kv * (kp * (qg[i] - q) - (q - q2[c]) / (2.0 * dt))"
            " + dist[i])\n"
            "            q2[c] = q1[c]\n            q1[c] = q\n"
            "        if out_f.shape[0] > 0:\n"
            "            for c in range(C):\n"
            "                out_f[i, c] = uu[c]\n"),
    interval="pass", slope="", inputs="")

#: The base and force drivers' pieces: the input sampled, linearly interpolated in a sample.
_SAMPLED = dict(
    head="def integrate(u, n_sub, h, P, out_acc, out_z, out_v, ok):",
    prologue="    n = u.shape[0]", sample="", interval="ui = u[i]",
    slope="du = 0.0 if last else (u[i + 1] - ui) / n_sub",
    inputs=("            ua = ui + du * s\n            ub = ua + 0.5 * du\n"
            "            uc = ua + du\n"))


def _integrate_source(terms: tuple[Term, ...], driver: str) -> str:
    """``integrate``: RK4 over a block of particles (struct of arrays), the states kept
    finite (a particle beyond ``BLOW_UP`` is flagged and reset), z, z', z'' written out.
    The last sample's z'' is the first stage of one more step, whose states are not kept:
    the right-hand side stands in the loop once per stage and nowhere else (each copy is
    inlined; a fifth copy for the last sample cost 11 % of the compile time)."""
    params, states = _names(terms)
    n = len(states)
    ind = " " * 16
    load = "\n".join(f"    p_{p} = P[{j}]" for j, p in enumerate(params))
    init = "\n".join(f"    x{j} = np.zeros(C)" for j in range(n))
    check = " and ".join(f"abs(x{j}[c]) < BLOW_UP" for j in range(n))
    reset = "; ".join(f"x{j}[c] = 0.0" for j in range(n))
    step = "\n".join(ind + line for line in _step_source(terms, driver).splitlines())
    d = _SERVO if driver == "servo" else _SAMPLED
    return f"""{d["head"]}
    C = P.shape[1]
{load}
{init}
{d["prologue"]}
    scratch = np.empty(C)
    half = 0.5 * h
    sixth = h / 6.0
    for i in range(n):
{d["sample"]}{WRITES}        {d["interval"]}
        {d["slope"]}
        for s in range(1 if last else n_sub):
{d["inputs"]}            row = acc_row if s == 0 else scratch
            for c in range(C):
{step}
        if last:
            break
        for c in range(C):
            if not ({check}):
                ok[c] = False
                {reset}
"""


def source(terms: tuple[str, ...], driver: str) -> str:
    """The generated module's text for a structure and a driver."""
    if driver not in DRIVERS:
        raise ValueError(f"driver must be one of {DRIVERS}, got {driver!r}")
    objs = tuple(term(n) for n in terms)
    imports = []
    for i, t in enumerate(objs):
        for fn, local in (("force", "_force"), ("state_rates", "_rates"), ("masses", "_masses"),
                          ("displacement_update", "_update"), ("static", "_static"),
                          ("transition", "_transition")):
            if getattr(t, fn) is not None:
                imports.append(f'{local}{i} = compiled("{t.name}", "{fn}")')
    jit = '@nb.njit(error_model="numpy", cache=True'
    return "\n".join([
        f'"""Generated by harvester.model.codegen: structure ({", ".join(terms) or "linear"}),'
        f' driver {driver}. Do not edit."""',
        "import numba as nb", "import numpy as np", "",
        "from harvester.model.codegen import BLOW_UP, compiled, turning_point", "",
        *(["from harvester.model.stick import (MAX_EVENTS, TRANSITION_RATE_H, breakaway, "
           "crossing)", ""]
          if has_stick(objs) else []),
        *imports, "", "",
        f'{jit}, inline="always")', _rhs_source(objs, driver), "", "",
        *(_stick_source(objs, driver, {**(_SERVO if driver == "servo" else _SAMPLED),
                                       "writes": WRITES}, _names(objs), jit)
          if has_stick(objs) else
          [f"{jit}, nogil=True)", _integrate_source(objs, driver)])])


# --------------------------------------------------------------------------- the compiler

#: Where Numba's block-label counter is put back before a kernel compiles (``bound_labels``).
LABEL_START = 1 << 20


def bound_labels() -> None:
    """Put Numba's block-label counter back to LABEL_START before a kernel compiles.

    Numba numbers the blocks it inlines from one counter per process
    (``numba.core.ir_utils._the_max_label``), offsetting a callee's blocks by it; a callee
    that itself inlined (``rhs`` holding the terms' laws, inlined four times a step) brings
    labels of the counter's size, so the counter doubles at each such inline and a kernel
    adds 6-11 digits to it. After some tens of kernels in one process LLVM refuses the
    labels ("name is too long": the literature grid's runner failed at its 21st record,
    compiling from a cold cache). Within one function's compile the labels only need to
    exceed its own, which Numba ensures (``max(next(), max(blocks))``); between kernels the
    counter may start again. Put back so, it stays at 13-17 digits over seven kernels, with
    the same numbers out."""
    from numba.core import ir_utils
    counter = ir_utils._the_max_label
    counter._value = min(counter._value, LABEL_START)


# --------------------------------------------------------------------------- the cache


def cache_dir() -> Path:
    """Where generated kernels and their machine code live."""
    root = os.environ.get("HARVESTER_CACHE") or Path.home() / ".cache" / "harvester"
    return Path(root) / "kernels"


def _dependencies(terms: tuple[str, ...]) -> list[Path]:
    here = Path(__file__).parent
    deps = [Path(__file__), here / "fastmath.py", here / "acquisition.py",
            here / "terms" / "__init__.py", here / "stick.py"]
    return deps + [Path(term(n).source) for n in terms]


def _digest(text: str, terms: tuple[str, ...]) -> str:
    h = hashlib.sha256(text.encode())
    for path in _dependencies(terms):
        h.update(path.read_bytes())
    return h.hexdigest()[:16]


def _import(path: Path, name: str) -> ModuleType:
    spec = importlib.util.spec_from_file_location(name, path)
    module = importlib.util.module_from_spec(spec)
    sys.modules[name] = module
    spec.loader.exec_module(module)
    return module


def kernel(terms: tuple[str, ...], driver: str = "base") -> ModuleType:
    """The compiled kernel module of a structure (generated and imported once per process)."""
    key = (tuple(terms), driver)
    with _lock:
        if key in _modules:
            return _modules[key]
        text = source(key[0], driver)
        name = f"harvester_kernel_{driver}_{_digest(text, key[0])}"
        directory = cache_dir()
        directory.mkdir(parents=True, exist_ok=True)
        path = directory / f"{name}.py"
        if not path.exists() or path.read_text() != text:
            fd, tmp = tempfile.mkstemp(dir=directory, suffix=".tmp")
            with os.fdopen(fd, "w") as f:
                f.write(text)
            os.replace(tmp, path)
        _modules[key] = _import(path, name)
        return _modules[key]
