"""A simulated run (`Trajectory`): its samples, its CSV text, and its plot against time.

Joint positions q (rad or m), velocities qd and the applied torques tau (N m or N)
are sampled at the times t of the integrator (symdyn.apps.simulation.simulate); a tracked
reference (symdyn.apps.simulation.control) adds q_ref and qd_ref at the same times. The CSV
(symdyn.apps.simulation.csv_format) is written by the plant's compiled library when it has one.
"""

from __future__ import annotations

import os
from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np

from ...errors import SymdynError
from ...model.free_flyer_names import NQ_BASE
from ..identification.measurements import log_columns
from ..output import figure, figure_bytes, plot_format, write_atomic
from .csv_format import csv_bytes, csv_text

if TYPE_CHECKING:
    from ...model.robot import Robot
    from ..compilation.compile import CompiledDynamics

__all__ = ["Trajectory", "plot_trajectory"]


@dataclass
class Trajectory:
    """A simulated run: sample times t (N,), states q, qd and torque tau (N, n), or (N, B, n) for a batch.

    tau[k] is the torque at (t_k, q_k, qd_k), the one applied at the start of step k.
    `q_ref`, `qd_ref` hold a tracked reference at the same times (None without one);
    `plant` is the compiled robot that produced the run (None for one made by hand).
    """

    robot: Robot
    t: np.ndarray
    q: np.ndarray
    qd: np.ndarray
    tau: np.ndarray
    integrator: str
    q_ref: np.ndarray | None = None
    qd_ref: np.ndarray | None = None
    plant: CompiledDynamics | None = field(default=None, repr=False, compare=False)
    qdd: np.ndarray | None = None  # a floating robot's accelerations (forward dynamics at each sample)

    @property
    def n(self) -> int:
        return self.robot.n

    def _columns(self) -> tuple[list[str], np.ndarray]:
        if self.q.ndim != 2:
            raise SymdynError("CSV output holds one trajectory, not a batch")
        nq, nv = self.q.shape[1], self.qd.shape[1]
        if nq != nv:  # floating: the log symdyn identify reads (symdyn.apps.identification.measurements)
            columns = log_columns(nq - NQ_BASE, floating=True)
            values = {"t": self.t, "q": self.q, "qd": self.qd, "qdd": self.qdd, "tau": self.tau}
            heads = [head for head, a in values.items() if a is not None]  # qdd: None in a hand-made run
            header = [name for head in heads for name in columns[head]]
            return header, np.column_stack([values[head] for head in heads])
        header = ["t"] + [f"q{i}" for i in range(1, nq + 1)] + [f"qd{i}" for i in range(1, nv + 1)]
        return header, np.column_stack([self.t, self.q, self.qd])

    def csv_text(self) -> str:
        """Columns t, q1..qn, qd1..qdn, one row per sample, full double precision ("%.17g"); for a
        floating robot t, x_b y_b z_b qx_b qy_b qz_b qw_b, q1..qn, vx_b .. wz_b, qd1..qdn, then the
        accelerations ax_b .. dwz_b, qdd1..qddn and the efforts fx_b .. mz_b, tau1..taun (a log
        `symdyn identify` reads)."""
        return csv_text(*self._columns())

    def csv_bytes(self) -> bytes:
        """csv_text() encoded, written in C by the plant's compiled library when there is one."""
        return csv_bytes(*self._columns(), self.plant)

    def write_csv(self, path: str | os.PathLike) -> Path:
        """Write csv_bytes() atomically (temporary file in the same folder, then rename)."""
        return write_atomic(path, self.csv_bytes())


def plot_trajectory(traj: Trajectory, path: str | os.PathLike | None = None) -> bytes:
    """Joint positions and velocities against time; with a reference also the tracking error.

    Returns the image bytes; writes them atomically to `path` when given.
    """
    fmt = plot_format(path) if path is not None else "png"
    if traj.q.ndim != 2:
        raise SymdynError("plots show one trajectory, not a batch")
    tracking = traj.q_ref is not None
    fig = figure(3 if tracking else 2)
    axes = fig.subplots(3 if tracking else 2, 1, sharex=True)
    colors = [f"C{i % 10}" for i in range(traj.n)]
    for i in range(traj.n):
        axes[0].plot(traj.t, traj.q[:, i], color=colors[i], label=f"q{i + 1}")
        axes[1].plot(traj.t, traj.qd[:, i], color=colors[i], label=f"qd{i + 1}")
        if tracking:
            axes[0].plot(traj.t, traj.q_ref[:, i], "--", color=colors[i], label=f"q{i + 1} reference")
            if traj.qd_ref is not None:
                axes[1].plot(traj.t, traj.qd_ref[:, i], "--", color=colors[i], label=f"qd{i + 1} reference")
            err = np.abs(traj.q_ref[:, i] - traj.q[:, i])
            axes[2].semilogy(
                traj.t, np.maximum(err, 1e-16), color=colors[i], label=f"|q{i + 1}_ref - q{i + 1}|"
            )
    axes[0].set_ylabel("q (rad or m)")
    axes[1].set_ylabel("qd (rad/s or m/s)")
    if tracking:
        axes[2].set_ylabel("tracking error")
        axes[0].set_title(f"{traj.robot.name}: reference (dashed) and actual (solid), {traj.integrator}")
    else:
        axes[0].set_title(f"{traj.robot.name}: simulation ({traj.integrator})")
    axes[-1].set_xlabel("t (s)")
    for ax in axes:
        ax.grid(True, alpha=0.3)
        ax.legend(loc="upper right", fontsize="small", ncol=2)
    data = figure_bytes(fig, fmt)
    if path is not None:
        write_atomic(path, data)
    return data
