"""Compile MJCF files with MuJoCo in contained children of a server process (run as a script).

symdyn.parsers.mjcf_compile starts `python mjcf_run.py` once (a contained.Server) and sends it
requests {"file": path}. This process imports mujoco once; for each request it forks a child
that confines itself (symdyn.parsers.contained: its memory, CPU time, no processes, no writes),
compiles the file and answers {"warnings": [...]} with the model as MJB bytes, or {"error":
message}. MuJoCo's compiler allocates what a file asks (<replicate> nested deep, a huge hfield):
the child's bounds stop it, and a fork costs milliseconds where a new interpreter importing
mujoco costs half a second. This file imports the standard library, numpy, mujoco and its
sibling contained.py only, so that it runs without symdyn on the path.
"""

from __future__ import annotations

import contained  # this file's sibling (the script's folder is on sys.path)
import mujoco
import numpy as np


def compile_file(request: dict) -> tuple[dict, bytes]:
    """The answer to one request: ({"warnings": [...]}, MJB bytes) or ({"error": message}, b"")."""
    said: list[str] = []
    mujoco.set_mju_user_warning(said.append)  # MuJoCo would print its warnings itself
    try:
        model = mujoco.MjModel.from_xml_path(request["file"])
    except ValueError as exc:
        return {"error": str(exc), "warnings": said}, b""
    except MemoryError:
        return {"memory": True, "warnings": said}, b""
    buffer = np.zeros(mujoco.mj_sizeModel(model), dtype=np.uint8)
    mujoco.mj_saveModel(model, None, buffer)
    return {"warnings": said}, buffer.tobytes()


if __name__ == "__main__":
    contained.serve(compile_file, threads=True)
