"""Checkpoints of a pymoo run without pickle, and the exact restore of the algorithm.

A checkpoint is **one file**, ``checkpoint.npz`` (``np.savez``, read with
``allow_pickle=False``), replaced atomically and flushed to disk
(:func:`~adept_traj.files.write_atomic`): a crash at any instant leaves either the previous
generation's checkpoint or the new one, never a mix. It holds

- ``X`` (pop, n_var), ``F`` (pop, n_obj), ``G`` (pop, n_constr), ``CV`` (pop, 1) of the
  population and ``n_iter`` (0-d, the generation counter);
- ``data.<key>`` for every numeric per-individual attribute the algorithm keeps (e.g.
  ``data.rank`` (pop,), ``data.crowding`` (pop,)), and ``absent.<key>`` (pop,) bool for
  an attribute that only some members have (the members without it);
- ``loop.<key>``: arrays the loop adds (the feasible fronts of every generation so far);
- ``meta`` (0-d text): JSON with ``format`` = ``"adept_traj.checkpoint"``, ``version`` = 2,
  ``n_iter``, ``n_eval`` (the evaluation counter), ``rng`` (the state of the algorithm's
  ``numpy`` generator), ``arrays`` (every other array's name: its dtype and shape), and what
  the loop adds: ``fingerprint``, ``total_s`` [s], ``evaluation_s`` [s], ``history``.

A damaged file is refused by :func:`load_checkpoint` (and :func:`restore_algorithm`, which
checks the arrays against the algorithm's problem) with
:class:`~adept_traj.errors.CheckpointFormatError` naming the file and the array, before
anything is restored: truncated or not an ``.npz`` archive, an array missing or not
listed in ``arrays``, of another dtype or shape than listed, or than the population's
layout (``X``, ``F``, ``G``, ``CV`` float64 of one row per member, ``n_iter`` a 0-d
integer, ``data.<key>`` one row per member, ``absent.<key>`` bool (pop,)). A checkpoint
written before ``arrays`` was kept (and version 1) is checked against the layout only.

Version 1 (the same arrays, the metadata in a second file ``checkpoint.json``) is still
read, so a run interrupted by an earlier release resumes.

This module is the **only** one that relies on pymoo's internals (tested by
``tests/optimise/test_checkpoint.py``, so that a pymoo upgrade that changes them fails there with a
clear message):

- ``Algorithm._initialize()`` (resets ``n_iter``, ``pop`` and ``opt`` before a restore) and
  ``Algorithm._set_optimum()`` (recomputes ``opt`` from the restored population);
- the attributes ``Algorithm.pop``, ``n_iter`` (the generation being run: a finished
  generation g leaves g + 1), ``is_initialized``, ``random_state`` (the
  ``numpy.random.Generator`` from which every operator draws), ``evaluator.n_eval`` and
  ``termination`` (its ``update(algorithm)`` sets the progress from ``n_iter``, before
  pymoo counts the generation);
- ``Individual.data`` (the dict of per-individual attributes such as rank and crowding) and
  ``Individual.evaluated`` (the set of evaluated values; the evaluator skips an individual
  whose set holds F, G and H, so restored members are not evaluated again).
"""

from __future__ import annotations

import json
from pathlib import Path
from typing import Any

import numpy as np
from pymoo.core.population import Population

from adept_traj.errors import CheckpointFormatError, ConfigurationError
from adept_traj.files import parse_json, read_bytes_bounded, write_atomic
from adept_traj.optimise.operators.population import population_values
from adept_traj.optimise.search.checkpoint_checks import (
    check_layout,
    check_listed,
    check_meta,
    described,
    read_arrays,
)

__all__ = [
    "CHECKPOINT_FILE",
    "CHECKPOINT_VERSION",
    "CapturedCheckpoint",
    "capture_checkpoint",
    "checkpoint_arrays",
    "has_checkpoint",
    "load_checkpoint",
    "restore_algorithm",
    "save_checkpoint",
    "write_checkpoint",
]

#: Version of the checkpoint file (``meta`` key ``version``); version 1 is still read.
CHECKPOINT_VERSION = 2

#: The checkpoint's file in its folder.
CHECKPOINT_FILE = "checkpoint.npz"

_ARRAYS, _META_V1 = CHECKPOINT_FILE, "checkpoint.json"

_FORMAT = "adept_traj.checkpoint"
#: Keys the loop stores in ``checkpoint.json`` besides the algorithm's counters.
_LOOP_KEYS = {"fingerprint", "total_s", "evaluation_s", "history"}
#: Values the evaluator must not compute again for a restored individual.
_EVALUATED = ("F", "G", "H")


def _population_arrays(
    pop: Population, n_iter: int, data: list[dict[str, Any]] | None = None
) -> dict[str, np.ndarray]:
    """Numeric per-individual attributes of ``pop`` as arrays (for the checkpoint), with the
    generation counter so that the two checkpoint files can be checked against each other;
    ``data`` the members' ``data`` dicts (default: as they are now).

    An attribute that only some members have (NSGA-II ranks only the feasible ones) is
    stored with the mask ``absent.<key>`` (pop,) of the members without it."""
    data = [ind.data for ind in pop] if data is None else data
    out = {key: population_values(pop, key) for key in ("X", "F", "G", "CV")}
    out["n_iter"] = np.array(n_iter)
    for key in sorted({key for d in data for key in d}):
        values = [d.get(key) for d in data]
        have = np.array([v is not None for v in values])
        present = np.array([v for v in values if v is not None])
        if present.dtype == object:
            continue  # not storable without pickle (and not needed by pymoo's operators)
        full = np.zeros((len(pop), *present.shape[1:]), dtype=present.dtype)
        full[have] = present
        out[f"data.{key}"] = full
        if not have.all():
            out[f"absent.{key}"] = ~have
    return out


def _restore_population(arrays: dict[str, np.ndarray]) -> Population:
    """The population of ``arrays``, marked evaluated (the evaluator skips its members)."""
    pop = Population.new(X=arrays["X"])
    pop.set("F", arrays["F"], "G", arrays["G"], "CV", arrays["CV"])
    for name, values in arrays.items():
        if name.startswith("data."):  # (n_iter is checked by load_checkpoint, not stored)
            key = name.removeprefix("data.")
            have = ~arrays.get(f"absent.{key}", np.zeros(len(pop), dtype=bool))
            pop[have].set(key, values[have])
    for ind in pop:
        ind.evaluated.update(_EVALUATED)
    return pop


def has_checkpoint(folder: Path) -> bool:
    """Whether ``folder`` holds a checkpoint (of any version) to resume from."""
    return (folder / _ARRAYS).is_file()


def save_checkpoint(
    folder: Path,
    algorithm: Any,
    meta: dict[str, Any],
    extra: dict[str, np.ndarray] | None = None,
) -> None:
    """Write the checkpoint of ``algorithm`` (after a finished generation) into ``folder``:
    :func:`write_checkpoint` of :func:`checkpoint_arrays`.

    Parameters
    ----------
    folder:
        Created if missing; ``checkpoint.npz`` is replaced atomically (one file: a crash
        leaves the previous checkpoint or this one).
    algorithm:
        A set-up, initialised pymoo algorithm.
    meta:
        JSON-ready values stored with it (the loop's ``fingerprint``, ``total_s`` [s],
        ``evaluation_s`` [s] and ``history``).
    extra:
        Further numeric arrays of the caller, stored as ``loop.<key>``.
    """
    write_checkpoint(folder, checkpoint_arrays(algorithm, meta, extra))


def checkpoint_arrays(
    algorithm: Any, meta: dict[str, Any], extra: dict[str, np.ndarray] | None = None
) -> dict[str, np.ndarray]:
    """The content of the checkpoint of ``algorithm`` as it is now (after a finished
    generation), for :func:`write_checkpoint`: new arrays and the metadata as JSON text, so
    that later generations change nothing in it (parameters as :func:`save_checkpoint`)."""
    return capture_checkpoint(algorithm).arrays(meta, extra)


class CapturedCheckpoint:
    """What the checkpoint of an algorithm after a finished generation is made of, taken
    without building its arrays (see :func:`capture_checkpoint`)."""

    def __init__(self, algorithm: Any) -> None:
        # The members' X, F, G and CV never change once evaluated; their data dicts (rank,
        # crowding) are rewritten by later survivals, so they are copied.
        self._members = list(algorithm.pop)
        self._data = [dict(ind.data) for ind in self._members]
        self._n_iter = int(algorithm.n_iter)
        self._n_eval = int(algorithm.evaluator.n_eval)
        self._rng = algorithm.random_state.bit_generator.state

    def arrays(
        self, meta: dict[str, Any], extra: dict[str, np.ndarray] | None = None
    ) -> dict[str, np.ndarray]:
        """The checkpoint's arrays, as :func:`checkpoint_arrays` made them when this was
        captured (``meta`` and ``extra`` as there)."""
        pop = Population(self._members) if self._members else Population()
        arrays = _population_arrays(pop, self._n_iter, self._data)
        arrays.update({f"loop.{key}": np.asarray(value) for key, value in (extra or {}).items()})
        state = {
            "format": _FORMAT,
            "version": CHECKPOINT_VERSION,
            "n_iter": self._n_iter,
            "n_eval": self._n_eval,
            "rng": json.loads(json.dumps(self._rng, default=int)),
            **meta,
        }
        state["arrays"] = {name: [a.dtype.str, list(a.shape)] for name, a in arrays.items()}
        arrays["meta"] = np.array(json.dumps(state))
        return arrays


def capture_checkpoint(algorithm: Any) -> CapturedCheckpoint:
    """The checkpoint of ``algorithm`` as it is now (after a finished generation), its
    arrays made only when asked for (:meth:`CapturedCheckpoint.arrays`, e.g. when it is
    written): the members, a copy of their ``data``, the counters and the generator's
    state. Making the arrays every generation would cost the main process time for
    nothing: the loop writes about one generation in ten."""
    return CapturedCheckpoint(algorithm)


def write_checkpoint(folder: Path, arrays: dict[str, np.ndarray]) -> None:
    """Write the ``arrays`` of :func:`checkpoint_arrays` as ``folder/checkpoint.npz``
    (``folder`` created if missing), replaced atomically and flushed to disk."""
    folder.mkdir(parents=True, exist_ok=True)

    def write_npz(path: Path) -> None:
        with path.open("wb") as fh:
            np.savez(fh, **arrays)

    write_atomic(folder / _ARRAYS, write_npz)
    (folder / _META_V1).unlink(missing_ok=True)  # of a version-1 checkpoint resumed here


def load_checkpoint(folder: Path) -> tuple[dict[str, Any], dict[str, np.ndarray]]:
    """Read a checkpoint folder: (metadata, arrays of ``checkpoint.npz`` without ``meta``).

    Raises
    ------
    CheckpointFormatError
        A damaged file (see the module's docstring): truncated, not an ``.npz`` archive, an
        array missing, unexpected, or of the wrong shape or dtype, malformed metadata.
    ConfigurationError
        No checkpoint in ``folder``, another format or version, or (version 1) files of
        two different generations.
    """
    npz_path = folder / _ARRAYS
    if not npz_path.is_file():
        raise ConfigurationError(f"{folder}: no checkpoint to resume ({_ARRAYS})")
    arrays = read_arrays(npz_path)
    # Version 2 keeps its metadata inside; version 1 beside it in checkpoint.json. Both are
    # parsed by the bounded parser (size, nesting, no NaN or infinity: none is ever written).
    version = CHECKPOINT_VERSION if "meta" in arrays else 1
    if version > 1:
        text = arrays.pop("meta")
        if text.shape != () or text.dtype.kind != "U":
            raise CheckpointFormatError(
                npz_path, "meta", f"{described(text)} where 0-d text (JSON) is stored"
            )
        meta = parse_json(str(text).encode("utf-8"), f"{npz_path} (meta)", ConfigurationError)
    elif not (folder / _META_V1).is_file():
        raise CheckpointFormatError(
            npz_path, "meta", f"missing, and no {_META_V1} (of version 1) beside it"
        )
    else:
        meta = parse_json(_read_meta_v1(folder), str(folder / _META_V1), ConfigurationError)
    if not isinstance(meta, dict) or (meta.get("format"), meta.get("version")) != (
        _FORMAT,
        version,
    ):
        raise ConfigurationError(f"{folder}: not an adept_traj checkpoint of version {version}")
    meta_file, meta_name = (npz_path, "meta") if version > 1 else (folder / _META_V1, None)
    needed = {"n_iter", "n_eval", "rng"} | _LOOP_KEYS
    if missing := sorted(needed - set(meta)):
        raise CheckpointFormatError(meta_file, meta_name, f"missing the values {missing}")
    if missing := sorted({"X", "F", "G", "CV", "n_iter"} - set(arrays)):
        raise CheckpointFormatError(npz_path, None, f"missing the arrays {missing}")
    check_meta(meta_file, meta_name, meta)
    if "arrays" in meta:
        check_listed(npz_path, arrays, meta["arrays"])
    check_layout(npz_path, arrays)
    if int(arrays["n_iter"]) != meta["n_iter"]:
        # Version 1, interrupted between its two renames: the files are of two generations.
        raise ConfigurationError(
            f"{folder}: checkpoint.npz (generation {int(arrays['n_iter']) - 1}) and "
            f"its metadata (generation {meta['n_iter'] - 1}) disagree; cannot resume exactly"
        )
    return meta, arrays


def _read_meta_v1(folder: Path) -> bytes:
    """The bytes of a version-1 checkpoint's ``checkpoint.json`` (at most
    :data:`~adept_traj.files.MAX_FILE_BYTES`)."""
    path = folder / _META_V1
    if not path.is_file():
        raise ConfigurationError(f"{folder}: incomplete checkpoint, missing {_META_V1}")
    return read_bytes_bounded(path, ConfigurationError, what="checkpoint metadata")


def restore_algorithm(
    algorithm: Any,
    meta: dict[str, Any],
    arrays: dict[str, np.ndarray],
    file: str | Path = _ARRAYS,
) -> None:
    """Put a freshly set-up ``algorithm`` into the state of a checkpoint (from
    :func:`load_checkpoint`): population, generation and evaluation counters, random
    generator and current optimum. The next ``ask`` continues exactly where the
    checkpointed run stopped.

    Raises
    ------
    CheckpointFormatError
        (named ``file``) The arrays do not fit the algorithm's problem: ``X`` not
        (pop, n_var) or not finite, ``F`` not (pop, n_obj), ``G`` not (pop, n_ieq_constr), or the
        generator's state of another bit generator than the algorithm's. Checked before
        anything of ``algorithm`` changes.
    """
    problem = algorithm.problem
    for name, n, what in (
        ("X", problem.n_var, "n_var"),
        ("F", problem.n_obj, "n_obj"),
        ("G", problem.n_ieq_constr, "n_ieq_constr"),
    ):
        if arrays[name].shape[1:] != (n,):
            raise CheckpointFormatError(
                file, name, f"{described(arrays[name])} where the problem has {what} = {n}"
            )
    if not np.isfinite(arrays["X"]).all():
        raise CheckpointFormatError(file, "X", "NaN or infinite decision variables")
    kind = type(algorithm.random_state.bit_generator).__name__
    if meta["rng"].get("bit_generator") != kind:
        raise CheckpointFormatError(
            file, "meta", f"'rng' is a state of {meta['rng'].get('bit_generator')}, not {kind}"
        )
    algorithm._initialize()
    algorithm.pop = _restore_population(arrays)
    algorithm.is_initialized = True
    algorithm.evaluator.n_eval = meta["n_eval"]
    algorithm.random_state.bit_generator.state = meta["rng"]
    # What pymoo does after finishing generation g = n_iter - 1, in its order: the optimum,
    # the termination's progress (so a checkpoint of the last generation runs no further
    # one), then the count.
    algorithm.n_iter = meta["n_iter"] - 1
    algorithm._set_optimum()
    algorithm.termination.update(algorithm)
    algorithm.n_iter = meta["n_iter"]
