"""simulate's options of a robot in contact with the world (--contacts, --impulse-at, --stance,
--restitution, --baumgarte, --pd) and the run they ask for (symdyn.apps.simulation.contact_simulate;
docs/contacts.md)."""

from __future__ import annotations

import argparse
import math

import numpy as np

from ..errors import SymdynError
from .common import add_contacts_argument

__all__ = ["contact_arguments", "check_contact_options", "pd_torque", "stance_entries", "CONTACT_ONLY"]

#: the options that apply with --contacts only
CONTACT_ONLY = ("impulse_at", "stance", "restitution", "baumgarte", "pd")


def contact_arguments(s) -> None:
    """simulate's options of a robot in contact (symdyn.cli.apps)."""
    add_contacts_argument(s)
    s.add_argument(
        "--impulse-at",
        type=float,
        metavar="T",
        help="--contacts: free before T (s), then a touchdown impulse (impulse dynamics) and held",
    )
    s.add_argument(
        "--stance",
        nargs="+",
        metavar="T=NAME,NAME",
        help="--contacts: the contacts that hold from time T (s) on, the others free (T= : none); "
        "before the first T every contact holds; a contact that starts to hold gets a touchdown "
        "impulse",
    )
    s.add_argument(
        "--restitution",
        type=float,
        metavar="E",
        help="--impulse-at, --stance: the restitution of a touchdown in [0, 1] (default 0: the "
        "contacts stop)",
    )
    s.add_argument(
        "--baumgarte",
        nargs=2,
        type=float,
        metavar=("KP", "KD"),
        help="--contacts: Baumgarte's position (1/s^2) and velocity (1/s) gains (default 0 0: off)",
    )
    s.add_argument(
        "--pd",
        nargs=2,
        type=float,
        metavar=("KP", "KD"),
        help="--contacts: a joint PD controller holding the joints at --q0's, tau = KP (q0 - q) - KD qd "
        "(in place of --tau)",
    )


def check_contact_options(args: argparse.Namespace) -> None:
    """Refuse the contact options without --contacts, and values that are not finite, negative gains,
    a restitution outside [0, 1], a touchdown outside (0, duration] and --pd beside --tau or --track."""
    if args.contacts is None:
        for opt in CONTACT_ONLY:
            if getattr(args, opt) is not None:
                raise SymdynError(f"--{opt.replace('_', '-')} applies with --contacts only")
        return
    for opt in ("track", "kp", "kd", "model_params"):
        if getattr(args, opt) is not None:
            raise SymdynError(f"--{opt.replace('_', '-')} does not apply with --contacts (use --pd or --tau)")
    if args.pd is not None and args.tau is not None:
        raise SymdynError("--pd and --tau exclude each other (--pd computes the torque)")
    for opt in ("baumgarte", "pd"):
        values = getattr(args, opt)
        if values is not None and not all(math.isfinite(v) and v >= 0 for v in values):
            raise SymdynError(
                f"--{opt}: the gains must be finite numbers >= 0, got {' '.join(map(str, values))}"
            )
    if args.stance is not None:
        if args.impulse_at is not None:
            raise SymdynError(
                "--impulse-at and --stance exclude each other (--impulse-at T is --stance 0= T=ALL)"
            )
        args.stance = stance_entries(args.stance, args.duration)
    if args.restitution is not None:
        if args.impulse_at is None and args.stance is None:
            raise SymdynError("--restitution applies with --impulse-at or --stance only")
        if not 0.0 <= args.restitution <= 1.0:
            raise SymdynError(f"--restitution {args.restitution}: must be in [0, 1]")
    if args.impulse_at is not None and not 0.0 < args.impulse_at <= args.duration:
        raise SymdynError(
            f"--impulse-at {args.impulse_at}: must lie in (0, {args.duration:g}] s, the run's time"
        )


def pd_torque(args: argparse.Namespace, q0: np.ndarray, nv: int):
    """--pd KP KD as tau(t, q, qd), or None."""
    from ..apps.simulation.contact_simulate import joint_pd

    return None if args.pd is None else joint_pd(q0, args.pd[0], args.pd[1], nv)


def stance_entries(values: list[str], duration: float) -> list[tuple[float, tuple[str, ...]]]:
    """--stance T=NAME,NAME ... as [(T, names)]: T a finite number in [0, duration], increasing;
    the names are checked against the contacts by the simulation. SymdynError otherwise."""
    out: list[tuple[float, tuple[str, ...]]] = []
    for text in values:
        time, sep, names = text.partition("=")
        try:
            t = float(time) if sep else math.nan
        except ValueError:
            t = math.nan
        if not math.isfinite(t):
            shown = text if len(text) <= 40 else text[:37] + "..."
            raise SymdynError(f"--stance {shown!r}: expected T=NAME,NAME,... (T in s, a number)")
        if not 0.0 <= t <= duration:
            raise SymdynError(f"--stance {t:g}: the time must lie in [0, {duration:g}] s, the run's time")
        if out and not t > out[-1][0]:
            raise SymdynError(f"--stance: the times must increase ({t:g} s after {out[-1][0]:g} s)")
        out.append((t, tuple(n for n in names.split(",") if n)))
    return out
