"""hydrocyl: hydraulic single-rod cylinder drives from Python.

Rigs (presets or rig JSON files) edited by the same parameter paths as the
CLI's ``--set``, runs as named numpy arrays in SI units (pressures in Pa
gauge), batch runs on all cores, Leaney's X factor and the measured-data
diagnosis. Bad input raises ValueError with the CLI's one-line message; a
solver failure raises SimulationError; a run whose constant-B oil cavitates
far below vacuum is returned with a CavitationWarning, one whose command
turns a pump past its maximum speed with a RatingWarning. Array arguments
are real numbers (ints or floats, any layout: unaligned, big-endian or
strided arrays are read as their values); complex numbers, booleans and
elements that are not numbers are a TypeError naming the argument.
"""

import os
from typing import Any, Iterator, Literal, Mapping, Optional, Sequence, Union

import numpy as np
import numpy.typing as npt

__version__: str
PRESETS: list[str]
"""Names of the built-in rigs (``Rig.load(name)``)."""
MAX_THREADS: int
"""The largest ``threads`` that ``simulate_batch`` takes (1024)."""

ArrayLike = npt.ArrayLike
Solver = Literal["auto", "dp45", "rosenbrock", "rk4", "exponential"]
"""``auto`` (the default, as the CLI's ``--solver``): Dormand–Prince 5(4)
while the run is not stiff, Rosenbrock while it is; ``dp45``,
``rosenbrock``; the fixed-step ``rk4`` and ``exponential`` (steps of
``rk4_step``)."""
ParamValue = Union[float, int, str, bool, None]

class SimulationError(Exception):
    """The solver failed (step size too small, too many steps, a non-finite
    state). The message names the method, the time and the state."""

    time: float
    """Time the solver reached [s] (NaN if it could not be located)."""
    state: dict[str, float]
    """State at ``time``: state name -> value (SI)."""

class CavitationWarning(UserWarning):
    """A chamber pressure fell far below absolute vacuum (below -10 bar
    gauge) in a run that did not blow up (no non-finite value, none below
    the liquid's tension limit of -1000 bar): the oil, a liquid of constant
    bulk modulus, has left its range from then on (the chamber cavitates).
    The run is returned; the message names the chamber, its lowest pressure
    and when, and the remedy (entrained air, ``<cylinder>.air_fraction``,
    where the cylinder's type has it). Warned by ``Rig.simulate`` and, per
    parameter set, ``simulate_batch``."""

class ParameterWarning(UserWarning):
    """A rig parameter inside its range but far outside what real rigs have
    (a bulk modulus of 7000 Pa, a bore area of 1963 m^2, an oil density of
    0.87 kg/m^3): the mark of a value written in another unit (bar, mm^2,
    g/cm^3), which runs and gives consistent nonsense. The run is returned;
    the message names the parameter by its ``Rig.set`` path, the usual span
    and the unit the value was likely meant in (the CLI's warning). Warned by
    ``Rig.simulate`` and, per parameter set, ``simulate_batch``."""

class RatingWarning(UserWarning):
    """The command goes beyond the limit of what the run's input drives: a
    normalised spool demand outside +-1 (the spool's stroke: the valve
    clamps it there), or a pump driven in volts turned past its maximum
    speed (its ``displacement`` and ``max_speed``; the pump is not limited
    to it, its flow follows the command). The run is returned. The message
    is the CLI's warning after ``command (t, u): ``: the count of samples
    beyond, the largest and when (for a pump, the rated speed and the
    command reaching it, and the largest's speed). Warned once per run by ``Rig.simulate`` and, per
    parameter set and naming it, by ``simulate_batch``."""

class Rig:
    """A rig: kind and parameters as in its JSON file (SI units, pressures
    in Pa gauge), checked after every edit. Picklable (as its JSON)."""

    @staticmethod
    def load(name_or_path: Union[str, os.PathLike[str]]) -> Rig:
        """A preset by name or a rig JSON file by path (``--rig``): a
        duplicate key is refused, an older kind (``valve-cylinder``,
        ``hybrid-pump``) is read as its netlist."""
    @staticmethod
    def from_json(text: str) -> Rig:
        """A rig from rig-file JSON text, read as ``load`` reads a file
        (messages name it ``JSON text``)."""
    @staticmethod
    def presets() -> list[str]:
        """Names of the built-in presets."""
    @property
    def kind(self) -> str:
        """The rig kind: ``netlist`` (older kinds are read as netlists)."""
    def set(self, path: str, value: ParamValue) -> None:
        """Sets one parameter as ``--set path=value`` does, then checks the
        rig; on error (ValueError) the rig is unchanged. SI units; None
        sets ``null`` (e.g. an initial pressure computed from the steady
        state)."""
    def update(self, values: Mapping[str, ParamValue]) -> None:
        """Sets several parameters, then checks the rig once;
        ``rig.update(rig.parameters())`` changes no value (defaults are written out)."""
    def get(self, path: str) -> Any:
        """The value at a parameter path: a number, or None for ``null``; for
        an inner path — a component (``"cylinder"``) or a group in one
        (``"valve.orifice"``) — a dict of the parameters under it, nested as
        their paths are (``rig.get("valve")["orifice"]["cd"] ==
        rig.get("valve.orifice.cd")``). ValueError for a path the rig does
        not have."""
    def parameters(self) -> dict[str, Optional[float]]:
        """Every numeric parameter, ``{path: value}`` (SI, defaults filled
        in; None for ``null``, e.g. an initial pressure the rig computes)."""
    def describe(self) -> dict[str, dict[str, Any]]:
        """Every parameter: ``{path: {"value", "unit", "doc"}}``, the values
        of ``parameters()``, the SI unit and meaning from the component
        registry (``hydrocyl components``); None where a rig declares none."""
    def to_json(self) -> str:
        """The rig as rig-file JSON text (``--print-rig``)."""
    def copy(self) -> Rig: ...
    def simulate(
        self,
        t: ArrayLike,
        u: ArrayLike,
        *,
        solver: Solver = "auto",
        rtol: float = 1e-6,
        rk4_step: float = 2e-5,
        h_max: Optional[float] = None,
        ledger: bool = False,
    ) -> Run:
        """Simulates on the command ``u`` at times ``t`` [s] (linear between
        samples) and samples the run at ``t``; ``t`` and ``u`` are 1-D
        (ValueError naming the argument otherwise). ``rtol`` in [1e-14, 1)
        (below 1e-14 double precision cannot meet it: ValueError). ``u``: normalised spool
        demand (valve rigs) or drive voltage [V] (pump rigs). ``rk4_step``
        and ``h_max`` (default 0.01) in s. ``ledger=True`` adds
        ``run.ledger``. Releases the GIL; runs the rig as it is when called
        (a ``set`` from another thread meanwhile does not change the run).
        SimulationError when the solver fails or the run blows up (a
        non-finite value, a chamber pressure below -1000 bar); a chamber
        far below vacuum short of that warns (CavitationWarning) and the
        run is returned; so does a command beyond the maximum speed of the
        pump it drives (RatingWarning). Ctrl-C (SIGINT) stops the run within a few tens
        of milliseconds with KeyboardInterrupt."""

class Run:
    """One run: ``time`` [s] and channels in SI (``units``): ``command``,
    ``position`` [m], ``velocity`` [m/s], ``p1``, ``p2`` [Pa gauge], then
    the rig's other outputs. ``run["position"]`` is a channel; iterating a
    run gives the channel names, as a dict its keys. The arrays are the
    run's own, not copies, and read-only (``flags.writeable`` is False).
    A run pickles bit for bit (Dask process/distributed schedulers)."""

    @property
    def time(self) -> npt.NDArray[np.float64]: ...
    @property
    def names(self) -> list[str]: ...
    @property
    def channels(self) -> dict[str, npt.NDArray[np.float64]]: ...
    @property
    def units(self) -> dict[str, str]: ...
    @property
    def stats(self) -> dict[str, Union[int, float]]:
        """``steps``, ``rejected``, ``rhs_evals``, ``jac_evals``,
        ``lu_decomps``, ``events`` and ``wall_s`` [s]."""
    @property
    def diagnostics(self) -> dict[str, float]:
        """Component counters: cavitation entries, end-stop impacts, ..."""
    @property
    def ledger(self) -> Optional[dict[str, Any]]:
        """Energy ledger over the run (``ledger=True``), else None: the
        object ``hydrocyl simulate --ledger`` writes, key for key. Energies
        in J (``components_j``: each component's ``source``, ``dissipated``,
        ``storage``, ``load``, ``moved``; ``totals_j``; ``energy_in_j``,
        ``cylinder_out_j``, ``losses_j`` by component (a plastic impact at a
        stroke end is the mass's loss), ``moving_walls_j``, ``closure_j``,
        ...), ``closure_relative`` (= ``error``) and ``storage_error`` as
        fractions of ``reference_j`` (the energy in; where none comes in,
        the largest other term), ``efficiency`` (None where no energy comes
        in)."""
    def __getitem__(self, name: str) -> npt.NDArray[np.float64]: ...
    def __contains__(self, name: str) -> bool: ...
    def __iter__(self) -> Iterator[str]:
        """The channel names (as ``keys()``)."""
    def keys(self) -> list[str]: ...
    def to_pandas(self) -> Any:
        """A pandas DataFrame (``time`` and the channels); ImportError
        without pandas, which hydrocyl does not require."""

class BatchRun:
    """Runs of ``simulate_batch``: per channel an ``(N, len(time))`` array,
    row i from parameter set i (SI units as in ``Run.units``). Iterating
    gives the channel names; ``len`` is the number of runs. The arrays are
    read-only, as a ``Run``'s; a batch pickles bit for bit."""

    @property
    def time(self) -> npt.NDArray[np.float64]: ...
    @property
    def names(self) -> list[str]: ...
    @property
    def units(self) -> dict[str, str]:
        """``{channel: SI unit}`` of the channels kept, as ``Run.units``
        (``command`` in V on a pump rig)."""
    @property
    def channels(self) -> dict[str, npt.NDArray[np.float64]]: ...
    @property
    def params(self) -> dict[str, npt.NDArray[np.float64]]: ...
    @property
    def stats(self) -> dict[str, npt.NDArray[np.float64]]:
        """Per run: ``steps``, ``rejected``, ``rhs_evals``, ``wall_s`` [s]."""
    @property
    def ok(self) -> npt.NDArray[np.bool_]: ...
    @property
    def errors(self) -> list[Optional[str]]: ...
    @property
    def interval_s(self) -> tuple[float, float]:
        """Start and end of the runs, ``time.time()`` scale [s], measured
        with the GIL released."""
    def __len__(self) -> int: ...
    def __getitem__(self, name: str) -> npt.NDArray[np.float64]: ...
    def __contains__(self, name: str) -> bool: ...
    def __iter__(self) -> Iterator[str]:
        """The channel names (as ``keys()``)."""
    def keys(self) -> list[str]: ...

def simulate_batch(
    rig: Rig,
    t: ArrayLike,
    u: ArrayLike,
    params: Mapping[str, ArrayLike],
    *,
    solver: Solver = "auto",
    rtol: float = 1e-6,
    rk4_step: float = 2e-5,
    h_max: Optional[float] = None,
    channels: Optional[Sequence[str]] = None,
    threads: Optional[int] = None,
    on_error: Literal["raise", "nan"] = "raise",
) -> BatchRun:
    """Runs ``rig`` once per parameter set (``params``: path -> N values,
    SI) in parallel with the GIL released; results in set order,
    independent of ``threads`` (1 to ``MAX_THREADS``, more is a ValueError;
    default: all cores; at most one thread per run is started).
    ``channels`` (default: all) is a list of the channel names kept (a
    single str is a TypeError), and only they are read in each run. A set
    whose chamber falls far below vacuum without blowing up is kept and
    warned of (CavitationWarning naming the set). Ctrl-C (SIGINT) stops
    every run with KeyboardInterrupt."""

def xfactor(gamma: float, travel: ArrayLike) -> npt.NDArray[np.float64]:
    """Leaney's X factor (dimensionless) for area ratio ``gamma`` = A1/A2
    at each normalised spool travel (spool position / underlap)."""

def diagnose(
    rig: Rig,
    record: Union[
        str,
        os.PathLike[str],
        Mapping[str, ArrayLike],
        Sequence[Union[str, os.PathLike[str], Mapping[str, ArrayLike]]],
    ],
    *,
    min_share: float = 0.03,
    holdout: float = 0.3,
    window: Optional[int] = None,
    effects: Union[str, Sequence[str], None] = None,
) -> dict[str, Any]:
    """``hydrocyl diagnose`` on any rig the CLI diagnoses (a friction bench
    such as ``emps`` or ``tudelft-seal-25``, or a netlist with a cylinder on
    a mass such as ``leaney-moog`` or ``wang-hybrid``; another is a
    ValueError naming why) and one measured record (CSV path or dict of
    arrays by column name, SI or with unit suffixes, read through the rig's
    ``identify.columns``) or a list of records fitted jointly (a friction
    bench; a record given twice is refused); the report as a dict, the
    JSON of ``--report``. ``window`` is at least 2 (a narrower one interpolates
    the order-3 smoother's coefficients). ``effects``: the effect ids the
    loop may add, a list or one string (split at commas, as the CLI's
    ``--effects``); any other type is a TypeError naming ``effects``."""
