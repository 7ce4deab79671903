"""`symdyn.compile`: a robot's generated functions as fast Python methods, from a cached C library.

The robot is derived and its code generated once (symdyn.codegen: the C target, the
NumPy target and the batch wrappers of symdyn.codegen.c.runtime); the C is compiled
with the system's compiler for this machine (symdyn.apps.compilation.build) into a shared library, and all of
it is stored in the cache (symdyn.apps.compilation.cache) under a hash of the robot's content,
symdyn's version and the options. The next call for the same robot loads the library
without deriving anything.

Every generated function becomes a method of `CompiledDynamics` with the generated
function's name and inputs (without p, which is bound): whatever the code generator
emits, including functions with several outputs (returned as a tuple) or outputs that
are not square. One state (vectors of their size) runs one C call; a batch (leading
axes, e.g. (B, n)) runs one call of NAME_batch, W states per instruction, optionally in
threads (symdyn.apps.compilation.calling: the layout, when arrays are passed without a copy).
NAME_batch is in a library of its own, built and cached when a batch call first needs it
(symdyn.apps.compilation.batch_library): a robot only called one state at a time, or only
simulated, never pays for the batch wrappers' compile. A robot with
closed loops also gets `solve_loops`, the generated C NAME_solve_loops (one state, or a batch
looped in C; symdyn.apps.compilation.calling.solve_loops_method). Joint
quantities are in joint space (rad or m), the base frame fixes gravity, as in
docs/generated-code.md. The robot's cache key is symdyn.apps.compilation.robot_key's.

The methods bind through cffi's ABI mode: measured on this machine, a 7-joint function called with
NumPy arrays costs about 2.7 us through cffi (ffi.from_buffer) against 5.8-6.3 us through
ctypes (docs/speed.md). cffi parses the declarations when a method is first used (about
0.1 s), so the stepping loop, called once per run, goes through ctypes instead. Without a C
compiler the methods are the generated NumPy module's, with one warning.

What an entry holds and how it is built: symdyn.apps.compilation.entry; the free parameters'
values: symdyn.apps.compilation.parameter_binding.
"""

from __future__ import annotations

import json
import types
import warnings
from collections.abc import Callable

from ...errors import SymdynError, SymdynWarning
from ...generated_modules import load_module
from . import cache
from .batch_library import batch_entry
from .calling import c_method, check_threads, load_library, numpy_solve_loops, solve_loops_method
from .compiled_frames import FrameMethods
from .configuration_check import quaternion_checked
from .contact_check import contact_checked
from .entry import build_options, entry_builder, loaded_files
from .parameter_binding import RobotInfo, bind_parameters
from .robot_key import robot_digest
from .singular import INVERTING, NotGeneratedError, guarded

__all__ = ["CompiledDynamics", "RobotInfo", "compile", "robot_digest", "cached_dynamics"]

#: The slowdown the fallback warning quotes (measured, docs/speed.md).
_FALLBACK_NOTE = (
    "about 10 times slower per call from Python (Panda forward dynamics: ~130 us against ~12 us) and "
    "about 300 times slower in simulations, whose loop then runs in Python instead of C; "
    "install a C compiler (cc, gcc or clang) or set CC"
)
_warned = False


def cached_dynamics(
    key_parts: dict,
    make_robot: Callable,
    params=None,
    method: str = "newton-euler",
    threads: int = 1,
    functions: tuple[str, ...] | None = None,
):
    """A CompiledDynamics from the cache entry of `key_parts` (plus the options), built when missing.

    make_robot() is called only to build the entry (a cache hit never derives nor loads it);
    the result then carries a RobotInfo instead of the Robot. A hit verifies the digest of the
    file it loads (the library); the others are verified when first read (cache.Entry.file).
    `functions`: the groups to build (checked names of symdyn.codegen.functions.GROUPS, or "all";
    None: symdyn.codegen.context's default groups); `key_parts` must tell them apart.
    """
    check_threads(threads)
    options = build_options(method)
    key = cache.entry_key(**key_parts, **options)
    entry = cache.lookup(key, loaded_files)
    robot = None
    chosen = None if functions is None else {"functions": list(functions)}
    if entry is None:
        robot = make_robot()
        entry = cache.get_or_build(key, entry_builder(robot, method, options, chosen))
    self = CompiledDynamics._from_entry(entry, robot, params)
    self.threads = threads
    self._source = ({**key_parts, "method": method}, make_robot)
    self._build_frames = lambda robot, folder, frames: entry_builder(robot, method, options, frames)(folder)
    self._options = options

    def rebuild() -> cache.Entry:
        made = robot if robot is not None else make_robot()
        return cache.get_or_build(key, entry_builder(made, method, options, chosen))

    self._rebuild = rebuild
    return self


def _function_groups(functions) -> tuple[str, ...] | None:
    """`functions` checked: None, or group names of symdyn.codegen.functions.GROUPS (a single name
    or a sequence; "all" for every group), as `symdyn generate --functions` takes them."""
    if functions is None:
        return None
    from ...codegen.functions import GROUPS

    names = (functions,) if isinstance(functions, str) else functions
    try:
        names = tuple(names)
    except TypeError:
        names = (functions,)
    unknown = [g for g in names if not isinstance(g, str) or (g not in GROUPS and g != "all")]
    if unknown or not names:
        raise SymdynError(
            f"symdyn.compile: unknown function group(s) {', '.join(map(repr, unknown)) or '(none given)'} "
            f"(one or more of {', '.join(GROUPS)}, or all)"
        )
    return tuple(GROUPS) if "all" in names else tuple(dict.fromkeys(names))


def compile(
    robot, params=None, method: str = "newton-euler", threads: int = 1, functions=None, batch: str = "lazy"
) -> CompiledDynamics:
    """The robot's generated functions compiled to C, with its free parameters bound to `params`.

    params: None (no free parameters), a map name -> value, or one value per free parameter
    in the robot's order. threads: how many threads a batch call uses by default (each method
    also takes threads=; symdyn.apps.compilation.calling). functions: the groups of generated functions to
    build, as `symdyn generate --functions` (names of symdyn.codegen.functions.GROUPS, or "all");
    None: the default ones (every group but kinematics, operational_space and centroidal; dynamics
    and configuration for a floating robot). The library is built for the machine it runs on
    (symdyn.apps.compilation.build: -march=native unless $SYMDYN_MARCH says otherwise) and cached under the
    robot, the options and the groups (docs/speed.md: the cache); the second compile of an
    unchanged robot loads it in milliseconds.

    batch: "lazy" (the default) builds the scalar library only (the generated functions, one state
    per call, and the stepping loop of `simulate`); the batch library (the batch wrappers
    NAME_batch, about as much compiler work again) is built and cached when a call first needs it:
    a batch (leading axes), `batch_width`, `solve_loops` on a batch
    (symdyn.apps.compilation.batch_library). "eager" builds both now, one after the other.

    Raises:
        SymdynError: not a Robot, bad parameter values, an unknown group, a `batch` other than
            "lazy" or "eager", or (eager) a failed build of the batch library.
    """
    from ...model.robot import Robot

    if not isinstance(robot, Robot):
        raise SymdynError(f"symdyn.compile expects a Robot, not {type(robot).__name__}")
    groups = _function_groups(functions)
    if batch not in ("lazy", "eager"):
        raise SymdynError(f'symdyn.compile: batch must be "lazy" or "eager", not {batch!r}')
    if robot.params:  # the values pass the robot file's physical checks (mass >= 0, ...)
        from ...model.physical import check_values

        check_values(robot, robot.param_values(params, "symdyn.compile"), "symdyn.compile")
    from ...codegen.functions import FAMILIES

    families = [f"{f.__module__}.{f.__qualname__}" for f in FAMILIES]
    key = {"robot": robot_digest(robot), "families": families}
    if groups is not None:  # (the default's key is unchanged: its cache entries stay valid)
        key["functions"] = list(groups)
    compiled = cached_dynamics(key, lambda: robot, params, method, threads, groups)
    if batch == "eager" and compiled.backend == "c":
        compiled._batch_loaded()
    return compiled


class CompiledDynamics(FrameMethods):
    """The generated functions of a robot as methods, bound to values of its free parameters.

    CompiledDynamics(robot, params) is symdyn.compile(robot, params). `backend` is "c" or
    "numpy" (no C compiler); `functions` names the methods; `module` is the generated
    NumPy module; `robot` the Robot (or a RobotInfo when it came from the cache alone).
    """

    def __init__(
        self, robot, params=None, method: str = "newton-euler", threads: int = 1, functions=None, batch="lazy"
    ) -> None:
        other = compile(robot, params, method, threads, functions, batch)
        self.__dict__.update(other.__dict__)

    @classmethod
    def _from_entry(cls, entry: cache.Entry, robot, params) -> CompiledDynamics:
        self = cls.__new__(cls)
        meta = entry.meta
        info = meta["robot"]
        self.robot = robot if robot is not None else RobotInfo(info["name"], info["n"], tuple(info["params"]))
        self.param_names = tuple(info["params"])
        self.p = bind_parameters(info["params"], self.robot, params)
        self._entry = entry
        self._params = params
        self._frame_libraries: dict = {}
        self.threads = 1
        self.frame_names = tuple(info.get("frames", ()))
        self._module = None
        self.functions = tuple(f["name"] for f in meta["functions"])
        self._library = entry.file(meta["library"]) if meta["library"] else None
        self.backend = "c" if self._library is not None else "numpy"
        if self._library is None:
            _warn_fallback()
            for f in meta["functions"]:
                method = quaternion_checked(f, contact_checked(f, _numpy_method(self, f["name"])), self.n)
                setattr(self, f["name"], guarded(self, f["name"], method))
        return self

    def __getattr__(self, name: str):
        """The C methods, bound on first use (cffi parses the declarations then: ~0.1 s)."""
        entry = self.__dict__.get("_entry")
        if entry is not None and name in INVERTING and name not in self.__dict__.get("functions", ()):
            raise NotGeneratedError(self.robot.name, name)
        if entry is None or name not in self.__dict__.get("functions", ()) or self._library is None:
            raise AttributeError(f"'CompiledDynamics' object has no attribute '{name}'")
        ffi, lib = self._loaded()
        p_ptr = ffi.NULL if self.p is None else ffi.from_buffer("double[]", self.p)
        for f in entry.meta["functions"]:
            called = c_method(ffi, lib, f, p_ptr, self, self._batch_library)
            method = quaternion_checked(f, contact_checked(f, called), self.n)
            setattr(self, f["name"], guarded(self, f["name"], method))
        return self.__dict__[name]

    def _loaded(self, path=None, ffi=None) -> tuple:
        """(ffi, lib) of the scalar library, or of the library at `path` with the scalar one's `ffi`
        (symdyn.apps.compilation.calling.load_library)."""
        meta = self._entry.meta
        solve = meta.get("solve_loops")
        functions = meta["functions"]
        return load_library(path or self._library, functions, self._width_symbol, solve=solve, ffi=ffi)

    @property
    def _width_symbol(self) -> str:
        """The C name of the library's NAME_batch_width function."""
        return f"{self._entry.meta['robot']['name']}_batch_width"

    def _batch_loaded(self) -> tuple:
        """(lib, W) of the batch library (NAME_batch ...), built and cached on the first call that needs
        it, once whichever threads call at once (symdyn.apps.compilation.batch_library)."""
        loaded = self.__dict__.get("_batch")
        if loaded is None:
            try:
                entry = batch_entry(self._entry)
            except cache.CorruptEntryError:  # a file of the scalar entry changed: build that again
                if "_rebuild" not in self.__dict__:
                    raise
                self._entry = self._rebuild()
                entry = batch_entry(self._entry)
            ffi, _ = self._loaded()
            _, lib = self._loaded(entry.file(entry.meta["library"]), ffi)
            loaded = self._batch = (lib, int(getattr(lib, self._width_symbol)()))
        return loaded

    def _batch_library(self):
        """The batch library's cffi lib (built on first use: _batch_loaded)."""
        return self._batch_loaded()[0]

    def solve_loops(self, qa, q_guess, threads: int | None = None):
        """Close the loops of a robot with closed loops: (iterations, q), q with its actuated entries
        qa and its passive ones solved by Newton's method from q_guess (the generated C
        NAME_solve_loops: docs/closed-loops.md), iterations -1 when it does not converge. One state
        gives (int, q of shape (n,)), as the NumPy module's solve_loops; a batch (leading axes on qa
        or q_guess) gives (iterations of the leading shape, q of shape (..., n)), looped in C, in
        `threads` threads (the default: this object's)."""
        solve = self._entry.meta.get("solve_loops")
        if solve is None:
            raise SymdynError(f"symdyn.compile: robot '{self.robot.name}' has no closed loops to solve")
        if self._library is None:  # the NumPy module's, one state per call
            return numpy_solve_loops(self.module, qa, q_guess, self.p)
        if "_solve_loops" not in self.__dict__:
            ffi, lib = self._loaded()
            p_ptr = ffi.NULL if self.p is None else ffi.from_buffer("double[]", self.p)
            self._solve_loops = solve_loops_method(ffi, lib, solve, p_ptr, self, self._batch_library)
        return self._solve_loops(qa, q_guess, threads)

    @property
    def batch_width(self) -> int:
        """W, the states a batch call evaluates per instruction (8 with AVX-512, 4 with AVX, else 1;
        1 on the NumPy backend). It is the batch library's: asking builds it when it is not built."""
        if self._library is None:
            return 1
        return self._batch_loaded()[1]

    @property
    def cdll(self):
        """The scalar library through ctypes (loads in microseconds; simulation.stepping calls it once per
        run): every generated function's one-state C function, symdyn_simulate (the stepping loop) and
        symdyn_csv, but not the batch wrappers NAME_batch, which are in the batch library built on the
        first batch call (symdyn.apps.compilation.batch_library)."""
        assert self.backend == "c"
        import ctypes

        return _CDLLS.setdefault(str(self._library), ctypes.CDLL(str(self._library)))

    def pointer(self, name: str) -> int:
        """The address of the one-state C function `name` in the scalar library (`cdll`; for the
        stepping loop's function pointers)."""
        import ctypes

        c_name = next(f["c_name"] for f in self._entry.meta["functions"] if f["name"] == name)
        return ctypes.cast(getattr(self.cdll, c_name), ctypes.c_void_p).value

    @property
    def n(self) -> int:
        return self.robot.n

    @property
    def module(self) -> types.ModuleType:
        """The generated NumPy module of the robot (NAME_numpy.py from the cache entry)."""
        if self._module is None:
            name = self._entry.meta["numpy"]
            try:
                path = self._entry.file(name)
            except cache.CorruptEntryError:  # changed since it was built: build the entry again
                self._entry = self._rebuild()
                path = self._entry.file(name)
            # symdyn's own output for this robot, verified against the cache manifest's digest,
            # imported from its file (never exec'd from a string)
            self._module = load_module(path, path.stem)
        return self._module

    def derived_entry(self, kind: str, build: Callable) -> cache.Entry:
        """A further cache entry of this robot, e.g. its task-space kinematics (analysis.task_space).

        Keyed like the robot's own entry plus `kind`; on a miss build(robot, folder) writes its
        files and returns its metadata, the Robot loaded only then when it came from the cache.
        """
        parts, make_robot = self._source
        key = cache.entry_key(**parts, kind=kind)
        entry = cache.lookup(key)
        if entry is None:
            robot = self.robot if not isinstance(self.robot, RobotInfo) else make_robot()
            entry = cache.get_or_build(key, lambda folder: build(robot, folder))
        return entry

    def function(self, name: str) -> Callable:
        """The generated function `name` (one of `functions`), also where a method of this class
        has its name (a frame's functions may: frame_pose, com, ...)."""
        if name not in self.__dict__:
            if name not in self.functions:
                raise SymdynError(f"symdyn.compile: no generated function {name!r}")
            return self.__getattr__(name)
        return self.__dict__[name]

    def frame_functions(self, frame: str, group: str = "kinematics", axes=None) -> CompiledDynamics:
        """The compiled functions of group `group` ("kinematics" or "operational_space", task axes
        `axes`, default all six) of one frame, in a cache entry of their own built on first use:
        methods <identifier>_pose, ..., com, ... (symdyn.codegen.frame_functions)."""
        from ...algorithms.operational_space import TASK_AXES, task_rows
        from ...model.frames import unknown_frame

        if frame not in self.frame_names:
            raise unknown_frame(frame, self.frame_names, f"symdyn.compile: robot '{self.robot.name}'")
        assert group in ("kinematics", "operational_space"), group
        task = ",".join(TASK_AXES[r] for r in task_rows(axes, "symdyn.compile: axes"))
        key = (frame, group, task)
        if key not in self._frame_libraries:
            options = {"functions": (group,), "frames": [frame], "task_axes": task}
            entry = self.derived_entry(  # keyed by the compiler options too, as the robot's own entry
                json.dumps({"frame": frame, "group": group, "axes": task, **self._options}, sort_keys=True),
                lambda robot, folder: self._build_frames(robot, folder, options),
            )
            frames = CompiledDynamics._from_entry(entry, self.robot, self._params)
            frames.threads = self.threads
            self._frame_libraries[key] = frames
        return self._frame_libraries[key]

    def __repr__(self) -> str:
        names = ", ".join(self.functions)
        return f"<CompiledDynamics {self.robot.name}: {self.n} joints, {self.backend}, {names}>"


def _warn_fallback() -> None:
    global _warned
    if not _warned:
        _warned = True
        warnings.warn(
            f"no C compiler found: using the generated NumPy module, {_FALLBACK_NOTE}",
            SymdynWarning,
            stacklevel=4,
        )


def _numpy_method(owner: CompiledDynamics, name: str) -> Callable:
    def call(*args, threads: int | None = None):  # the NumPy module vectorises itself: no threads
        return getattr(owner.module, name)(*args, owner.p)

    call.__name__ = name
    return call


_CDLLS: dict = {}
