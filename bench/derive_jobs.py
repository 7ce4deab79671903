"""The child process of bench/derive.py: one derivation, timed, counted and checked.

`job(kind, n, method, conn)` builds the robot (bench/robots.py), derives its equations of
motion by symdyn's "newton-euler" or "lagrange" or by sympy.physics.mechanics' KanesMethod
(bench/kane.py), and reports over the pipe `conn`, in this order:

* ("start", symdyn source digest) when the timed part begins,
* ("time", (wall s, CPU s)) when it ends,
* ("post", {"ops", "err", "scale"[, "build"]}): sympy.count_ops of tau, M, V, G and the
  largest |tau - symdyn.rnea.rnea| at one random state (joint space, base-frame gravity),

or ("error", text) at any point instead.
"""

from __future__ import annotations

import time

from derive_report import KANE
from machine import source_digest

__all__ = ["job", "SEED"]

SEED = 20240601


def _robot(kind: str, n: int):
    from robots import generic_arm, puma560_symbolic

    if kind == "puma":
        return puma560_symbolic()[0]
    return generic_arm(n)


def _random_state(robot):
    """q, qd, qdd uniform in [-1, 1] and (symbolic robots) parameter values in [0.05, 1]."""
    import numpy as np

    rng = np.random.default_rng(SEED + robot.n)
    q, qd, qdd = (rng.uniform(-1.0, 1.0, robot.n) for _ in range(3))
    params = rng.uniform(0.05, 1.0, len(robot.params)) if robot.params else None
    return q, qd, qdd, params


def _check(robot, state, tau) -> dict:
    """{"err": max |tau - symdyn.rnea.rnea|, "scale": max |rnea|} at `state`."""
    import numpy as np

    from symdyn.rnea import rnea

    q, qd, qdd, params = state
    ref = rnea(robot, q, qd, qdd, params)
    return {"err": float(np.max(np.abs(tau - ref))), "scale": float(np.max(np.abs(ref)))}


def _symdyn_job(robot, method: str, send) -> None:
    import sympy as sp

    from symdyn.dynamics import derive

    send(("start", source_digest()))
    t0, c0 = time.perf_counter(), time.process_time()
    dyn = derive(robot, method, simplify=False)
    send(("time", (time.perf_counter() - t0, time.process_time() - c0)))
    ops = {}
    for name in ("tau", "M", "V", "G"):
        exprs = [e for _, e in dyn.assignments((name,))] + list(dyn.compact[name])
        ops[name] = sum(sp.count_ops(e) for e in exprs)
    state = _random_state(robot)
    q, qd, qdd, params = state
    tau = dyn.evaluate("tau", q, qd, qdd, params)
    send(("post", {"ops": ops, **_check(robot, state, tau)}))


def _kane_job(robot, send) -> None:
    """KanesMethod on bench/kane.py's twin; tau = mass_matrix qdd - forcing."""
    import numpy as np
    import sympy as sp
    from kane import kane_model
    from sympy.physics.mechanics import KanesMethod

    t0 = time.perf_counter()
    model = kane_model(robot)
    build = time.perf_counter() - t0
    send(("start", source_digest()))
    t0, c0 = time.perf_counter(), time.process_time()
    km = KanesMethod(model.frame, q_ind=model.q, u_ind=model.u, kd_eqs=model.kd_eqs)
    km.kanes_equations(model.bodies, model.loads)
    send(("time", (time.perf_counter() - t0, time.process_time() - c0)))
    n = robot.n
    plain = {}
    for i in range(n):
        plain[model.q[i]] = sp.Symbol(f"q{i + 1}")
        plain[model.u[i]] = sp.Symbol(f"qd{i + 1}")
    M = km.mass_matrix.xreplace(plain)
    f = km.forcing.xreplace(plain)
    ops = {"M": sp.count_ops(list(M)), "V": sp.count_ops(list(f))}
    state = _random_state(robot)
    q, qd, qdd, params = state
    values = {sp.Symbol(f"q{i + 1}"): sp.Float(q[i], 17) for i in range(n)}
    values.update({sp.Symbol(f"qd{i + 1}"): sp.Float(qd[i], 17) for i in range(n)})
    if params is not None:
        values.update({p: sp.Float(v, 17) for p, v in zip(robot.params, params, strict=True)})
    Mn = np.array(M.xreplace(values).evalf(), dtype=float)
    fn = np.array(f.xreplace(values).evalf(), dtype=float).ravel()
    tau = Mn @ qdd - fn
    send(("post", {"ops": ops, **_check(robot, state, tau), "build": build}))


def job(kind: str, n: int, method: str, conn) -> None:
    """Run one derivation in this process and report over `conn` (see the module docstring)."""
    import warnings

    warnings.simplefilter("ignore")
    try:
        robot = _robot(kind, n)
        if method == KANE:
            _kane_job(robot, conn.send)
        else:
            _symdyn_job(robot, method, conn.send)
    except BaseException as exc:  # report anything, the parent prints it
        conn.send(("error", f"{type(exc).__name__}: {exc}"))
    finally:
        conn.close()
