"""Roger's arm identified by gradient descent through jax.grad (examples/jax_identification/README.md).

    python examples/jax_identification/identify.py

1. symdyn generates the JAX module of examples/roger_arm.yaml (free parameters g, l1, m1, l2,
   m2) into a temporary folder;
2. the numeric oracle symdyn.rnea makes the "measured" torques at the true parameters on
   random states (q, qd, qdd);
3. (l1, m1, l2, m2), g being known, are fitted from a wrong start by gradient descent (Adam
   steps, on their logarithms so that they stay positive) on the relative mean squared torque
   error, whose gradient jax.grad takes through the generated inverse dynamics, vmapped over
   the samples; the whole descent is one jax.lax.scan, jitted;
4. the true, starting and recovered values are printed, and the base parameters (the
   combinations the torques determine) with them.
"""

from __future__ import annotations

import importlib.util
import sys
import tempfile
from pathlib import Path

import jax
import numpy as np

jax.config.update("jax_enable_x64", True)  # the module is generated in double precision

import jax.numpy as jnp  # noqa: E402 (after the precision is chosen)

import symdyn  # noqa: E402
from symdyn.rnea import rnea  # noqa: E402

ROBOT = Path(__file__).resolve().parents[1] / "roger_arm.yaml"
G = 9.81
#: the parameters to recover (the module's PARAM_NAMES order is g, l1, m1, l2, m2)
TRUE = {"l1": 0.6, "m1": 1.4, "l2": 0.45, "m2": 0.9}
START = {"l1": 1.0, "m1": 1.0, "l2": 1.0, "m2": 1.0}


def base_parameters(l1, m1, l2, m2, g=G) -> np.ndarray:
    """The combinations the torques of Roger's arm determine (slide 18): m2 l2^2, m2 l1 l2,
    (m1 + m2) l1^2, (m1 + m2) g l1, m2 g l2."""
    return np.array([m2 * l2**2, m2 * l1 * l2, (m1 + m2) * l1**2, (m1 + m2) * g * l1, m2 * g * l2])


def generated_module(folder: Path):
    """NAME_jax.py of Roger's arm, generated into `folder` and imported."""
    (path,) = symdyn.generate(ROBOT, targets=("jax",), out_dir=folder)
    spec = importlib.util.spec_from_file_location("roger_arm_jax", path)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def samples(count: int, seed: int):
    """Random states and the oracle's torques at the true parameters."""
    rng = np.random.default_rng(seed)
    q = rng.uniform(-np.pi, np.pi, (count, 2))
    qd = rng.uniform(-2.0, 2.0, (count, 2))
    qdd = rng.uniform(-4.0, 4.0, (count, 2))
    robot = symdyn.load_robot(ROBOT)
    tau = rnea(robot, q, qd, qdd, {"g": G, **TRUE})
    return q, qd, qdd, tau


def identify(arm, q, qd, qdd, tau, steps: int = 15000) -> dict[str, float]:
    """(l1, m1, l2, m2) minimising the relative mean squared torque error, by Adam steps on their
    logarithms with the gradient of jax.grad, the learning rate decaying from 0.02 to 2e-4."""
    tau_batch = jax.vmap(arm.inverse_dynamics, in_axes=(0, 0, 0, None))
    scale = jnp.mean(tau**2)

    def loss(theta):
        p = jnp.concatenate([jnp.array([G]), jnp.exp(theta)])  # g, l1, m1, l2, m2
        return jnp.mean((tau_batch(q, qd, qdd, p) - tau) ** 2) / scale

    grad = jax.grad(loss)
    rates = 0.02 * (1e-2 ** (jnp.arange(steps) / steps))

    def adam(state, rate_k):
        theta, m, v, k = state
        g = grad(theta)
        m, v, k = 0.9 * m + 0.1 * g, 0.999 * v + 0.001 * g * g, k + 1
        step = rate_k * (m / (1 - 0.9**k)) / (jnp.sqrt(v / (1 - 0.999**k)) + 1e-12)
        return (theta - step, m, v, k), None

    theta0 = jnp.log(jnp.array([START[n] for n in ("l1", "m1", "l2", "m2")]))
    zeros = jnp.zeros_like(theta0)
    (theta, _, _, _), _ = jax.jit(lambda s: jax.lax.scan(adam, s, rates))((theta0, zeros, zeros, 0))
    return dict(zip(("l1", "m1", "l2", "m2"), np.exp(np.asarray(theta)).tolist(), strict=True))


def main() -> int:
    with tempfile.TemporaryDirectory() as folder:
        arm = generated_module(Path(folder))
        assert arm.PARAM_NAMES == ("g", "l1", "m1", "l2", "m2")
        q, qd, qdd, tau = samples(200, seed=1)
        found = identify(arm, q, qd, qdd, tau)
    print(f"{'':10}{'true':>10}{'start':>10}{'found':>12}")
    for name in TRUE:
        print(f"{name:10}{TRUE[name]:10.4f}{START[name]:10.4f}{found[name]:12.6f}")
    print("base parameters (m2 l2^2, m2 l1 l2, (m1+m2) l1^2, (m1+m2) g l1, m2 g l2):")
    print("  true ", np.array2string(base_parameters(**TRUE), precision=6))
    print("  found", np.array2string(base_parameters(**found), precision=6))
    return 0


if __name__ == "__main__":
    sys.exit(main())
