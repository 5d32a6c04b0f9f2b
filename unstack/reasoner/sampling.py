"""Approximate conditional marginals with error bars, for scenes too large to count.

Exact counting stops near 8 boxes (n = 9 has 6.3e10 consistent worlds). Beyond that the
marginals are estimated by Markov chain Monte Carlo over the consistent worlds themselves:

* the state of a chain is a preorder (a consistent world), so transitivity holds at every
  step by construction;
* a move takes one box out and inserts it again. Candidate insertions are proposed,
  deciding which boxes the box supports and which support it one box at a time (half of
  them decide the supported boxes first, half the supporting ones), each box joining with
  its own probability unless transitivity already decides it; the next state is drawn
  among the candidates and the current insertion with weights target / proposal (details
  in :mod:`unstack.reasoner._sampler_kernels`). Re-inserting single boxes connects every
  preorder to the empty one, so the chain reaches every consistent world -- single pair
  flips would not (three mutually supporting boxes cannot lose one relation alone);
* every sweep also redraws each pair whose two values both keep the world transitive
  (a Gibbs pass over pairs): local moves that keep the chain moving where every
  re-insertion proposal is far less probable than the current world (dense matrices of
  20 boxes and more, where re-insertion alone stalled at an acceptance of 0);
* a sweep is one pair pass, :data:`MOVES` re-insertions (the next boxes in turn; every box
  in a group of up to 8; in groups of more than 8 boxes the noisiest boxes of a pilot run
  come round more often, :mod:`unstack.reasoner.revisits`) and, after it, the record: each
  pair contributes the probability of its relation *given all the other relations*: the
  pair's own ``p`` whenever both values keep the world transitive, else the value
  transitivity leaves. This Rao-Blackwellisation
  removes the noise of the many pairs that transitivity does not touch (measured: it beats
  averaging the moved box's candidate relations, which was tried and dropped);
* several chains run in parallel, each from its own random world (one sweep that takes
  every proposal, starting from the closure of the hard evidence), so that chains which
  fail to mix disagree and widen the error bars instead of agreeing on their start; the
  first sweeps are discarded (burn-in), the rest are grouped into batches, and the standard error of
  every marginal comes from the spread of the batch means (batch means over all chains).

The estimate improves with time (anytime): give a number of recorded ``samples`` (sweeps,
over all chains; reproducible for a seed, whatever the machine's load; the default is
:data:`DEFAULT_SAMPLES`) or a ``time_limit`` in seconds (as many sweeps as fit, so not
reproducible from run to run). The validation on the benchmark sets, and
the coverage of the error bars, are on the docs page "Large scenes".

Examples
--------
>>> import numpy as np
>>> half = np.full((3, 3), 0.5); np.fill_diagonal(half, 0)
>>> result = sampled_marginals(half, samples=40_000, seed=0)
>>> abs(float(result.marginals[0, 1]) - 12 / 29) < 4 * float(result.standard_errors[0, 1]) + 1e-3
True
"""

from __future__ import annotations

import dataclasses
import time
from collections.abc import Callable
from concurrent.futures import ThreadPoolExecutor
from dataclasses import dataclass
from typing import Any

import numpy as np

from unstack.errors import InvalidArgument
from unstack.reasoner._chain_arrays import BlockArrays, ChainArrays
from unstack.reasoner.arguments import check_budget, check_count, check_matrix, check_samples, check_seed
from unstack.reasoner.forced_classes import forced_classes, quotient_probabilities, spread_pairs
from unstack.reasoner.progress import sampling_progress
from unstack.reasoner.revisits import schedule
from unstack.reasoner.world_masks import ONE_WORD_BOXES, mask_words, pack, unpack
from unstack.threads import even_ranges, thread_count

__all__ = [
    "DEFAULT_CHAINS",
    "DEFAULT_SAMPLES",
    "DEFAULT_TRIES",
    "MOVES",
    "RARE_SWEEPS",
    "WIDE_MOVES",
    "WIDE_SAMPLES",
    "SampledMarginals",
    "default_samples",
    "restrict_worlds",
    "sample_worlds",
    "sampled_marginals",
]

#: Independent chains (a range of them per thread of the call: every core by default, :mod:`unstack.threads`).
DEFAULT_CHAINS = 8
#: Recorded sweeps (over all chains) when neither ``samples`` nor ``time_limit`` is given and a
#: sweep re-inserts every box: reproducible for a seed (:func:`default_samples` scales it for
#: larger groups). When every sweep re-inserted every box, measured on the 39- and 40-box
#: classifier matrices of ``benchmarks/data`` (2 cores, both busy with other work): 0.98-1.07 s per group; 1024 and
#: 2048 sweeps took 0.34-0.37 s and 0.53-0.62 s (worst summed EC error 0.11 and 0.08 vs 0.06).
DEFAULT_SAMPLES = 4096
#: The default budget of a group of more than 63 boxes: its sweeps cost more (about 1 ms
#: for 150 boxes on one core against 0.06 ms for 40). On 150 boxes in 30 groups of 5 linked
#: by 1e-3 the worst EC error was 0.016-0.025 with 1024 sweeps and 0.013-0.017 with 2048
#: (benchmarks page, "Hundreds of boxes").
WIDE_SAMPLES = 2048
#: Proposals per move. Measured on the classifier matrices of two 39-40-box piles (1 s,
#: 4 seeds each, 2 free cores, against 100 s reference runs): mean worst EC error 0.0198 /
#: 0.0216 / 0.0275 with 1 / 2 / 3 proposals (worst 0.025 / 0.039 / 0.040); a second pass
#: over the pairs per sweep made it worse (0.023).
DEFAULT_TRIES = 1
#: Re-insertions per sweep in a group of more than 63 boxes (the boxes in turn; smaller groups
#: re-insert :data:`MOVES`). The pair pass, the block updates and the record
#: still cover every pair each sweep: on weakly linked groups they do most of the mixing,
#: and 150 boxes sampled about 3 times faster for about the same error (benchmarks/wide_moves.py).
WIDE_MOVES = 16
#: Re-insertions per sweep in a group of up to 63 boxes (the next boxes in turn; every box when
#: there are fewer). A sweep also runs the pair pass and records every pair, so fewer
#: re-insertions mean more, cheaper, sweeps in the same time. Measured on 8 classifier piles of
#: 37-40 boxes, 40 boxes in weakly linked groups and 24 dense boxes, 1 s per run, 3 seeds
#: (``benchmarks/narrow_moves.py``; docs page "Benchmarks"): mean worst EC error 0.039 / 0.038
#: / **0.029** / 0.037 on the piles with 64 (every box) / 16 / 8 / 4 re-insertions per sweep,
#: 0.013 / 0.008 / 0.010 / 0.010 on the weak groups, 0.38 / 0.42 / 0.30 / 0.35 on dense boxes.
MOVES = 8
#: Below this expected number of sweeps with a relation across a block, its ECs' standard
#: errors get the rare-event floor (:meth:`SampledMarginals.rare_event_floor`).
RARE_SWEEPS = 30
#: Sweeps per chain discarded before recording.
DEFAULT_BURN_IN = 64
#: The pilot run that chooses the revisit schedule takes one this-th of the budget; its records
#: are kept.
PILOT_SHARE = 8
#: Sweeps per chain in one round of the anytime loop (one call of the compiled kernel).
_ROUND_SWEEPS = 16
#: Rounds run by one call of the kernel on each thread (fewer hand-overs between threads), at most,
#: and the memory their records may take.
_MAX_ROUNDS = 8
_ROUND_BYTES = 1 << 25


def _rounds_to_run(
    most: int, recorded: int, sweep_targets: list[int | None], deadlines: list[float | None], round_seconds: float
) -> int:
    """Rounds of :data:`_ROUND_SWEEPS` sweeps for the next call of the kernel: at most ``most``, none
    past the next of ``sweep_targets`` (sweeps per chain: the budget, the end of the pilot), and
    none expected to end after the next of ``deadlines`` (one round while ``round_seconds`` is
    unknown). At least one.

    Examples
    --------
    >>> _rounds_to_run(8, 32, [200, 64], [None, None], 0.0)  # the pilot ends after two more rounds
    2
    """
    rounds = most
    for target in sweep_targets:
        if target is not None and target > recorded:
            rounds = min(rounds, -(-(target - recorded) // _ROUND_SWEEPS))
    now = time.perf_counter()
    for deadline in deadlines:
        if deadline is not None:
            rounds = min(rounds, int((deadline - now) / round_seconds) if round_seconds > 0 else 1)
    return max(1, rounds)


#: Batches kept per chain; when full, neighbours merge (batch length doubles).
_MAX_BATCHES = 32


@dataclass(frozen=True, eq=False)
class SampledMarginals:
    """Result of the sampling engine.

    Attributes
    ----------
    marginals : numpy.ndarray, shape (n, n)
        Estimated ``P(S_xy = 1 | consistent)``.
    standard_errors : numpy.ndarray, shape (n, n)
        Batch-means standard error of each estimate; inside a block at weak links at least
        the rare-event floor ``sqrt(link_rate / samples)`` (see :meth:`rare_event_floor`).
    batch_marginals : numpy.ndarray, shape (batches, n, n)
        The equal-length batch means the errors come from (every chain's batches).
    error_scale : float
        Factor from the spread of the batch means to the error of the estimate:
        ``1 / sqrt(batches)``, adjusted for the samples in the last, partial batch.
    chains : int
    samples : int
        Recorded sweeps over all chains.
    burn_in : int
        Discarded sweeps per chain.
    acceptance : float
        Share of accepted moves.
    seed : int or None
    seconds : float
        Wall time.
    block_of : numpy.ndarray, shape (n,), int64, optional
        Block of each box (``-1``: in none; :mod:`unstack.reasoner.block_gibbs`).
    link_rates : numpy.ndarray, shape (blocks,), optional
        Estimated relations across each block per sweep (the sum of the marginals of the pairs
        joining it to other boxes): the rate of the rare sweeps in which its exact
        marginals do not apply.
    final_worlds : numpy.ndarray, shape (chains, n) or (chains, n, words), int64, optional
        Last state of every chain (bit masks of the boxes each box supports, in the layout
        of :mod:`unstack.reasoner.world_masks`): a warm start for a related scene.
    schedule : numpy.ndarray, int64, optional
        The order in which the boxes were re-inserted at the end (every box once, unless the
        noisiest were visited more often: :mod:`unstack.reasoner.revisits`).
    """

    marginals: np.ndarray
    standard_errors: np.ndarray
    batch_marginals: np.ndarray
    error_scale: float
    chains: int
    samples: int
    burn_in: int
    acceptance: float
    seed: int | None
    seconds: float
    final_worlds: np.ndarray | None = None
    block_of: np.ndarray | None = None
    link_rates: np.ndarray | None = None
    schedule: np.ndarray | None = None

    def errors_of(self, weights: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Estimate and covariance of ``marginals @ weights`` (the expected costs).

        Returns
        -------
        values : numpy.ndarray, shape (n,)
        covariance : numpy.ndarray, shape (n, n)
            Covariance of the estimate: from the batch means, with every variance raised to
            at least the rare-event floor (:meth:`rare_event_floor`).
        """
        values = self.marginals @ weights
        batch_values = self.batch_marginals @ weights
        n = len(values)
        covariance = np.zeros((n, n))
        if len(batch_values) >= 2:
            covariance = np.atleast_2d(np.cov(batch_values, rowvar=False)) * self.error_scale**2
        floor = self.rare_event_floor(weights) ** 2
        covariance[np.diag_indices(n)] = np.maximum(np.diag(covariance), floor)
        return values, covariance

    def rare_event_floor(self, weights: np.ndarray) -> np.ndarray:
        """Smallest honest standard error of each ``marginals @ weights`` from rare sweeps.

        A block records its exact marginals in every sweep with no relation across it; the
        sweeps with one are rare at weak links (expected ``link_rate * samples`` of them), and a
        run may see none or a few, while its batch means see only those. Each such sweep can
        move a box's row by up to the largest weight in its block, so the count of such sweeps
        (Poisson, with the *expected* count, not the observed one) gives the floor
        ``max weight * sqrt(link_rate / samples)``. Applied only where fewer than
        :data:`RARE_SWEEPS` such sweeps are expected; with more the batch means see them.
        """
        floor = np.zeros(self.marginals.shape[0])
        if self.block_of is None or self.link_rates is None:
            return floor
        for inside, scale in _rare_blocks(self.block_of, self.link_rates, self.samples):
            floor[inside] = np.max(np.abs(weights[inside])) * scale
        return floor

    def convergence_of(self, weights: np.ndarray) -> np.ndarray:
        """Gelman-Rubin potential scale reduction (R-hat) of each ``marginals @ weights``.

        Computed from the batch means grouped by chain: near 1 when the chains, started from
        scattered worlds, agree as well as their own batches do; above about 1.1 they have
        not mixed and the standard errors are too small.
        """
        n = self.marginals.shape[0]
        values = (self.batch_marginals @ weights).reshape(self.chains, -1, n)
        batches = values.shape[1]
        if self.chains < 2 or batches < 2:
            return np.ones(n)
        within = values.var(axis=1, ddof=1).mean(axis=0)
        between = batches * values.mean(axis=1).var(axis=0, ddof=1)
        pooled = (batches - 1) / batches * within + between / batches
        # rounding alone (a group drawn exactly as one block records the same value every sweep)
        tiny = 1e-24 * np.maximum(1.0, values.mean(axis=(0, 1)) ** 2)
        with np.errstate(divide="ignore", invalid="ignore"):
            ratio = np.where(within > tiny, pooled / within, np.where(between > tiny, np.inf, 1.0))
        result: np.ndarray = np.sqrt(ratio)
        return result


def _rare_blocks(block_of: np.ndarray, link_rates: np.ndarray, samples: int) -> list[tuple[np.ndarray, float]]:
    """``(members, sqrt(link_rate / samples))`` of each block expecting fewer than
    :data:`RARE_SWEEPS` recorded sweeps with a relation across it (the rare-event floor's blocks)."""
    return [
        (block_of == k, float(np.sqrt(rate / samples)))
        for k, rate in enumerate(link_rates)
        if rate * samples < RARE_SWEEPS
    ]


def _moves(n: int) -> int:
    """Re-insertions per sweep in a group of ``n`` boxes."""
    return min(n, WIDE_MOVES if n > ONE_WORD_BOXES else MOVES)


def default_samples(n: int) -> int:
    """Recorded sweeps of a group of ``n`` boxes when no budget is given (reproducible).

    :data:`DEFAULT_SAMPLES` when a sweep re-inserts every box (up to :data:`MOVES` boxes);
    for larger groups up to 63 boxes, whose sweeps re-insert :data:`MOVES` boxes and so cost
    less, ``DEFAULT_SAMPLES * min(3, ceil(n / MOVES))``: three times the sweeps took about
    the time the former budget (4096 sweeps of every box) took on 37-40-box classifier piles
    and 1.2-2 times on 40 boxes in weakly linked groups, with smaller errors on both
    (``benchmarks/narrow_moves.py --sweeps``; docs page "Benchmarks"). More than 63 boxes:
    :data:`WIDE_SAMPLES`.

    Examples
    --------
    >>> default_samples(5), default_samples(12), default_samples(40), default_samples(150)
    (4096, 8192, 12288, 2048)
    """
    if n > ONE_WORD_BOXES:
        return WIDE_SAMPLES
    return DEFAULT_SAMPLES * min(3, -(-n // _moves(n)))


def _start_state(probabilities: np.ndarray, *, wide: bool) -> tuple[np.ndarray, np.ndarray]:
    """Bit masks of the transitive closure of the relations forced by probability 1."""
    n = probabilities.shape[0]
    reach = probabilities >= 1.0
    np.fill_diagonal(reach, False)
    for k in range(n):  # Warshall: runs once
        reach |= reach[:, k : k + 1] & reach[k : k + 1, :]
    np.fill_diagonal(reach, False)
    if np.any(reach & (probabilities <= 0.0)):
        raise InvalidArgument(
            "the relations forced by probability 1 imply one of probability 0; propagate evidence first"
        )
    return pack(reach, wide=wide), pack(reach.T, wide=wide)


def _transposed(successors: np.ndarray, n: int, *, wide: bool) -> np.ndarray:
    """Predecessor masks from successor masks (``(chains, n)`` or ``(chains, n, words)``)."""
    return pack(np.swapaxes(unpack(successors, n, wide=wide), -1, -2), wide=wide)


def restrict_worlds(worlds: np.ndarray, keep: np.ndarray) -> np.ndarray:
    """Chain states on the boxes ``keep`` (indices, in order) from states on more boxes.

    A preorder restricted to a subset of the boxes is a preorder of the subset, so the
    result is a consistent start for :func:`sampled_marginals` on those boxes. ``worlds``:
    ``(chains, n)`` masks, or ``(chains, n, words)`` for more than 63 boxes
    (:mod:`unstack.reasoner.world_masks`); the result has the layout of ``len(keep)`` boxes.

    Examples
    --------
    >>> restrict_worlds(np.array([[0b110, 0b100, 0]]), np.array([0, 2])).tolist()  # 0 -> 1 -> 2
    [[2, 0]]
    """
    keep = np.asarray(keep, dtype=np.int64)
    wide = worlds.ndim == 3
    n = worlds.shape[1]
    relation = unpack(worlds, n, wide=wide)[:, keep][:, :, keep]
    return pack(relation)


def _log_tables(probabilities: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """``log p`` and ``log(1 - p)``, with ``-inf`` where the factor is 0."""
    with np.errstate(divide="ignore"):
        return np.log(probabilities), np.log1p(-probabilities)


def _chain_seeds(seed: int | None, chains: int) -> np.ndarray:
    """One non-zero xorshift state per chain, from ``numpy.random.SeedSequence(seed)``."""
    states = np.random.SeedSequence(seed).generate_state(chains, dtype=np.uint64)
    states[states == 0] = np.uint64(0x9E3779B97F4A7C15)
    return states


#: A recorded sweep takes about this many times an unrecorded one (its conditionals are added up).
_RECORDING_COST = 1.6
#: Under a time limit, the burn-in's first sweeps are timed on their own (the scattering sweep
#: before them also compiles or loads the kernel): they tell what a sweep of the group costs.
_PROBE_SWEEPS = 4
#: A time limit is refused as unmeetable when the rest of a group's least sampling, estimated
#: from the probe, would take more than this many times the time left for it ...
_UNMEETABLE_FACTOR = 4.0
#: ... plus this many seconds (groups of the sizes of a container's detected boxes never do).
_UNMEETABLE_SLACK = 2.0


def _refuse_unmeetable_limit(n: int, sweep_seconds: float, burn_in_left: int, time_limit: float) -> None:
    """Raise :class:`~unstack.errors.TooLarge` when the rest of the least sampling of a group of
    ``n`` boxes (``burn_in_left`` sweeps and two recorded rounds, at ``sweep_seconds`` a sweep)
    cannot come near ``time_limit``: a planner with a budget gets an error it can act on after a
    few sweeps, not a decision minutes late (3,000 linked boxes with a limit of 2 s ran for over
    400 s).

    Examples
    --------
    >>> _refuse_unmeetable_limit(40, 0.0002, 60, 1.0)  # a container's group: nothing to say
    >>> _refuse_unmeetable_limit(1000, 0.06, 60, 0.2)
    Traceback (most recent call last):
    ...
    unstack.errors.TooLarge: a group of 1000 linked boxes needs about 7 s more of sampling at the least ...
    """
    from unstack.errors import TooLarge

    least = sweep_seconds * (burn_in_left + 2 * _ROUND_SWEEPS * _RECORDING_COST)
    if least > _UNMEETABLE_FACTOR * max(time_limit, 0.0) + _UNMEETABLE_SLACK:
        raise TooLarge(
            f"a group of {n} linked boxes needs about {least:.0f} s more of sampling at the least (a sweep takes "
            f"{sweep_seconds:.2g} s), with {max(time_limit, 0.0):.2g} s of the time limit left for it: the limit "
            "cannot be met; give a longer one, or decide on fewer boxes"
        )


class _Chains:
    """The state of ``chains`` chains on one probability matrix, started and burnt in.

    Each chain starts from the closure of the hard evidence, takes one sweep of every first
    proposal (scattered starts), then ``burn_in`` ordinary sweeps. The kernels
    (:mod:`unstack.reasoner._sampler_kernels`) keep a set of boxes as one 64-bit word in groups
    of up to 63 boxes and as an array of words in larger ones; ``wide=True`` forces the latter.
    """

    def __init__(
        self,
        probabilities: np.ndarray,
        *,
        chains: int,
        seed: int | None,
        burn_in: int,
        tries: int,
        blocks: bool = True,
        start: np.ndarray | None = None,
        wide: bool | None = None,
        deadline: float | None = None,
    ) -> None:
        from unstack.reasoner._sampler_kernels import run_chains
        from unstack.reasoner.block_gibbs import block_tables, strong_blocks

        n = probabilities.shape[0]
        self.wide = mask_words(n) > 0 if wide is None else wide
        self._run: Callable[..., None] = run_chains
        self.probabilities = probabilities
        self.log_tables = _log_tables(probabilities)
        successors, predecessors = _start_state(probabilities, wide=self.wide)
        self.successors = np.repeat(successors[None], chains, axis=0)
        self.predecessors = np.repeat(predecessors[None], chains, axis=0)
        self.rng = _chain_seeds(seed, chains)
        self.tries = tries
        self.accepted = np.zeros(chains, dtype=np.int64)
        self.max_rounds = max(1, min(_MAX_ROUNDS, _ROUND_BYTES // (8 * chains * n * n)))
        self.sums = np.zeros((chains, self.max_rounds, n, n))
        self.blocks = block_tables(probabilities, strong_blocks(probabilities) if blocks else [])
        self.linear_weights = np.exp(self.blocks.log_weights)
        self.moves = _moves(n)
        self.cursors = np.zeros(chains, dtype=np.int64)
        self.schedule = np.arange(n, dtype=np.int64)  # the order of the re-insertions
        self.moves_done = 0
        self._threads: int | None = None  # threads of the chains, chosen at the first round
        self._pool: ThreadPoolExecutor | None = None
        try:
            if start is None:
                self.advance(1, scatter=True)
            else:
                self.successors[:] = start
                self.predecessors[:] = _transposed(start, n, wide=self.wide)
            if deadline is not None and start is None and burn_in > _PROBE_SWEEPS:  # no limit: one call, as ever
                probed = time.perf_counter()
                self.advance(_PROBE_SWEEPS)
                now = time.perf_counter()
                _refuse_unmeetable_limit(n, (now - probed) / _PROBE_SWEEPS, burn_in - _PROBE_SWEEPS, deadline - now)
                self.advance(burn_in - _PROBE_SWEEPS)
            else:
                self.advance(burn_in)
        except BaseException:  # an error or Ctrl-C in the burn-in: no threads left behind
            self.close()
            raise

    def advance(self, sweeps: int, *, record: bool = False, scatter: bool = False, rounds: int = 1) -> None:
        """Run every chain ``rounds`` times ``sweeps`` sweeps; with ``record`` the conditionals of
        round ``r`` go to ``sums[:, r]``.

        A sweep re-inserts :data:`MOVES` boxes in turn, :data:`WIDE_MOVES` in a group of more
        than 63 boxes, every box in a smaller group (the scattering sweep re-inserts every box).
        """
        moves = self.probabilities.shape[0] if scatter else self.moves
        self.moves_done += len(self.rng) * sweeps * rounds * moves
        blocks = self.blocks
        arguments = (
            self.probabilities,
            *self.log_tables,
            ChainArrays(self.successors, self.predecessors, self.rng, self.cursors, self.accepted, self.sums),
            BlockArrays(
                blocks.members, blocks.sizes, blocks.counts, blocks.masks, blocks.log_weights, self.linear_weights,
                blocks.cumulative, blocks.marginals, blocks.pairs, blocks.block_of,
            ),
            sweeps,
            rounds,
            self.tries,
            record,
            scatter,
            moves,
            self.schedule,
        )  # fmt: skip
        if self._threads is None:  # the first round: the threads of this run
            self._threads = min(thread_count(), len(self.rng))
            if self._threads > 1:  # the calling thread runs the first range itself
                self._pool = ThreadPoolExecutor(self._threads - 1, thread_name_prefix="unstack-chains")
        ranges = even_ranges(len(self.rng), self._threads)
        if self._pool is None:
            for first, last in ranges:
                self._run(first, last, *arguments)
        else:
            futures = [self._pool.submit(self._run, first, last, *arguments) for first, last in ranges[1:]]
            try:
                self._run(*ranges[0], *arguments)
            finally:
                for future in futures:
                    future.result()

    def close(self) -> None:
        """Stop the threads of the chains (if any were started)."""
        if self._pool is not None:
            self._pool.shutdown(wait=True, cancel_futures=True)
        self._pool = None

    def __enter__(self) -> _Chains:
        return self

    def __exit__(self, *exc_info: object) -> None:
        self.close()


def sampled_marginals(
    probabilities: np.ndarray,
    *,
    samples: int | None = None,
    time_limit: float | None = None,
    seed: int | None = None,
    chains: int = DEFAULT_CHAINS,
    burn_in: int = DEFAULT_BURN_IN,
    tries: int = DEFAULT_TRIES,
    blocks: bool = True,
    wide: bool | None = None,
    insertion_sums: bool = False,
    revisits: bool = True,
) -> SampledMarginals:
    """Estimate the conditional marginals of the consistent worlds by MCMC.

    Parameters
    ----------
    probabilities : numpy.ndarray, shape (n, n)
        ``P(SUPP(i, j))``, diagonal ignored; exact 0 and 1 are hard evidence (propagate it
        first with :func:`~unstack.reasoner.pruning.propagate_evidence`).
    samples : int, optional
        Recorded sweeps over all chains; the run is reproducible for a given ``seed``.
        Neither this nor ``time_limit``: :func:`default_samples` of the group's size.
    time_limit : float, optional
        Seconds of sampling (burn-in included); not reproducible. With ``samples`` too,
        whichever comes first.
    seed : int, optional
        Seed of the chains' random streams.
    chains : int
        Independent chains, run in parallel.
    burn_in : int
        Sweeps per chain discarded first.
    tries : int
        Proposals per move (the move picks among them and the current relations).
    blocks : bool
        Redraw blocks of strongly linked boxes exactly after every sweep and record their
        exact conditional marginals (:mod:`unstack.reasoner.block_gibbs`); ``False`` runs
        the single-box moves alone.
    wide : bool, optional
        Run the kernels on word arrays (any number of boxes) even for 63 boxes or fewer,
        where they give the same numbers as on the default one-word sets, only more slowly;
        by default word arrays serve groups of 64 boxes and more.
    insertion_sums : bool
        Deprecated and ignored (it warns; it goes with 0.2): recording the noisiest boxes'
        rows by summing their insertion was measured no better than the pair record in the
        same time on classifier piles (docs page "Benchmarks", "Tried and measured no
        better") and is removed.
    revisits : bool
        In groups of more than 8 boxes, re-insert the noisiest boxes more often than the others, by
        the standard errors of a pilot run (the first eighth of the budget, kept;
        :mod:`unstack.reasoner.revisits`); ``False``: every box in turn.

    Returns
    -------
    SampledMarginals

    Raises
    ------
    InvalidArgument
        Not a square probability matrix, or a budget, seed or count out of its domain.
    TooLarge
        With ``time_limit``: the burn-in's first sweeps show that the rest of the least
        sampling (burn-in and two recorded rounds) would take more than 4 times the time left
        plus 2 s.
    """
    start = time.perf_counter()  # loading the compiled kernels counts against the time limit
    if insertion_sums:
        import warnings

        warnings.warn(
            "insertion_sums was measured no better than the pair record and is removed; it is ignored "
            "(and goes with 0.2)",
            DeprecationWarning,
            stacklevel=2,
        )
    p = check_matrix(probabilities)
    _check_sampling(samples, time_limit, seed, chains=chains, burn_in=burn_in, tries=tries)
    return _sampled_marginals(
        p,
        samples=samples,
        time_limit=time_limit,
        seed=seed,
        chains=chains,
        burn_in=burn_in,
        tries=tries,
        start=start,
        blocks=blocks,
        wide=wide,
        revisits=revisits,
    )


def _check_sampling(
    samples: Any, time_limit: Any, seed: Any, *, chains: Any = 1, burn_in: Any = 0, tries: Any = 1
) -> None:
    """Raise :class:`InvalidArgument` for a budget, seed or count out of its domain."""
    if samples is not None:
        check_samples(samples)
    if time_limit is not None:
        check_budget(time_limit, "time_limit")
    check_seed(seed)
    check_count(chains, "chains")
    check_count(tries, "tries")
    check_count(burn_in, "burn_in", minimum=0)


def _spread_over_boxes(merged: SampledMarginals, classes: np.ndarray) -> SampledMarginals:
    """The result of sampling the classes of :func:`~unstack.reasoner.forced_classes.forced_classes`,
    over the boxes: a box surely supports the others of its class, with no error."""
    return dataclasses.replace(
        merged,
        marginals=spread_pairs(merged.marginals, classes, 1.0),
        standard_errors=spread_pairs(merged.standard_errors, classes, 0.0),
        batch_marginals=spread_pairs(merged.batch_marginals, classes, 1.0),
        final_worlds=None,
        block_of=None if merged.block_of is None else merged.block_of[classes],
        schedule=None,
    )


def _sampled_marginals(
    p: np.ndarray,
    *,
    samples: int | None,
    time_limit: float | None,
    seed: int | None,
    chains: int = DEFAULT_CHAINS,
    burn_in: int = DEFAULT_BURN_IN,
    tries: int = DEFAULT_TRIES,
    start: float | None = None,
    blocks: bool = True,
    warm: np.ndarray | None = None,
    wide: bool | None = None,
    revisits: bool = True,
) -> SampledMarginals:
    """:func:`sampled_marginals` on checked arguments; ``warm``: consistent starting worlds,
    one per chain (skips the scattering sweep).

    Boxes that surely support each other are sampled as one (:mod:`unstack.reasoner.forced_classes`:
    one box's re-insertion cannot move such a class) and spread back over the boxes; such a run
    starts cold and keeps no final worlds.
    """
    start = time.perf_counter() if start is None else start
    classes = forced_classes(p)
    if classes is not None:
        merged = _sampled_marginals(
            quotient_probabilities(p, classes), samples=samples, time_limit=time_limit, seed=seed, chains=chains,
            burn_in=burn_in, tries=tries, start=start, blocks=blocks, wide=wide, revisits=revisits,
        )  # fmt: skip
        return _spread_over_boxes(merged, classes)
    n = p.shape[0]
    if samples is None and time_limit is None:
        samples = default_samples(n)
    deadline = None if time_limit is None else start + time_limit
    per_chain = None if samples is None else -(-samples // chains)
    watch = sampling_progress()
    if watch is not None:  # what is recorded: whole rounds of sweeps in every chain
        watch.start(n, None if per_chain is None else chains * -(-per_chain // _ROUND_SWEEPS) * _ROUND_SWEEPS)
    with _Chains(
        p, chains=chains, seed=seed, burn_in=burn_in, tries=tries, blocks=blocks, start=warm, wide=wide,
        deadline=deadline,
    ) as state:  # fmt: skip
        choosing = revisits and n > MOVES  # the pilot: the first part of the run
        pilot_sweeps = None if per_chain is None else max(2 * _ROUND_SWEEPS, per_chain // PILOT_SHARE)
        pilot_deadline = (
            None if deadline is None else time.perf_counter() + (deadline - time.perf_counter()) / PILOT_SHARE
        )

        batches = np.zeros((chains, _MAX_BATCHES, n, n))
        batch_length = _ROUND_SWEEPS  # sweeps per chain in one batch
        filled = 0  # complete batches per chain
        partial = 0  # sweeps per chain in the open batch
        recorded = 0  # sweeps per chain
        round_seconds = 0.0
        while True:
            rounds = _rounds_to_run(
                state.max_rounds,
                recorded,
                [per_chain, pilot_sweeps if choosing else None],
                [deadline, pilot_deadline if choosing else None],
                round_seconds,
            )
            call_start = time.perf_counter()
            state.sums[:, :rounds] = 0.0
            state.advance(_ROUND_SWEEPS, record=True, rounds=rounds)
            round_seconds = (time.perf_counter() - call_start) / rounds
            if watch is not None:
                watch.done = chains * (recorded + rounds * _ROUND_SWEEPS)
            for r in range(rounds):
                batches[:, filled] += state.sums[:, r]
                partial += _ROUND_SWEEPS
                recorded += _ROUND_SWEEPS
                if partial == batch_length:
                    filled += 1
                    partial = 0
                    if filled == _MAX_BATCHES:
                        batches[:, : _MAX_BATCHES // 2] = batches[:, 0::2] + batches[:, 1::2]
                        batches[:, _MAX_BATCHES // 2 :] = 0.0
                        filled = _MAX_BATCHES // 2
                        batch_length *= 2
            if (
                choosing
                and filled >= 2
                and (
                    (pilot_sweeps is not None and recorded >= pilot_sweeps)
                    or (pilot_deadline is not None and time.perf_counter() >= pilot_deadline)
                )
            ):
                choosing = False
                pilot = (batches[:, :filled] / batch_length).reshape(-1, n, n)  # the complete batch means so far
                variances = pilot.sum(axis=2).var(axis=0, ddof=1) / len(pilot)  # each box's EC, unit weights
                state.schedule = schedule(np.sqrt(variances))
                state.cursors[:] = 0
            if per_chain is not None and recorded >= per_chain:
                break
            if deadline is not None and time.perf_counter() + round_seconds >= deadline and filled >= 2:
                break  # the next round would end after the deadline

        if watch is not None:
            watch.finish()
        totals = batches.sum(axis=1)  # every recorded sweep, including the open batch
        marginals = totals.sum(axis=0) / (chains * recorded)
        batch_marginals = batches[:, :filled].reshape(chains * filled, n, n) / batch_length
        full_share = (filled * batch_length) / recorded
        error_scale = float(np.sqrt(full_share / (chains * filled)))
        spread = batch_marginals.std(axis=0, ddof=1) if len(batch_marginals) > 1 else np.zeros((n, n))
        np.fill_diagonal(marginals, 0.0)
        block_of = state.blocks.block_of
        link_rates = np.array(
            [
                marginals[block_of == k][:, block_of != k].sum() + marginals[block_of != k][:, block_of == k].sum()
                for k in range(len(state.blocks.sizes))
            ]
        )
        standard_errors = spread * error_scale
        for inside, scale in _rare_blocks(block_of, link_rates, chains * recorded):  # the floor of the pairs inside
            pairs = np.ix_(inside, inside)
            standard_errors[pairs] = np.maximum(standard_errors[pairs], scale)
        np.fill_diagonal(standard_errors, 0.0)
        moves = state.moves_done  # the scattering sweep, burn-in and recorded sweeps
        return SampledMarginals(
            marginals=marginals,
            standard_errors=standard_errors,
            batch_marginals=batch_marginals,
            error_scale=error_scale,
            chains=chains,
            samples=chains * recorded,
            burn_in=burn_in,
            acceptance=float(state.accepted.sum() / moves) if moves else 1.0,
            seed=seed,
            seconds=time.perf_counter() - start,
            final_worlds=state.successors.copy(),
            block_of=block_of,
            link_rates=link_rates,
            schedule=state.schedule.copy(),
        )


def sample_worlds(
    probabilities: np.ndarray,
    worlds: int,
    *,
    seed: int | None = None,
    thin: int = 1,
    burn_in: int = DEFAULT_BURN_IN,
    tries: int = DEFAULT_TRIES,
) -> np.ndarray:
    """Draw consistent worlds from one chain of the sampler (correlated draws).

    Parameters
    ----------
    probabilities : numpy.ndarray, shape (n, n)
    worlds : int
        Number of worlds.
    seed : int, optional
    thin : int
        Sweeps between two recorded worlds.
    burn_in, tries : int
        As in :func:`sampled_marginals`.

    Returns
    -------
    numpy.ndarray, shape (worlds, n, n), bool
        ``[k, i, j]``: box i supports box j in world k.

    Examples
    --------
    >>> import numpy as np
    >>> p = np.array([[0, 0.9, 0.1], [0.1, 0, 0.9], [0.1, 0.1, 0]])
    >>> draws = sample_worlds(p, 3, seed=0)
    >>> draws.shape
    (3, 3, 3)
    """
    p = check_matrix(probabilities)
    check_count(worlds, "worlds", minimum=0)
    check_count(thin, "thin")
    _check_sampling(None, None, seed, burn_in=burn_in, tries=tries)
    classes = forced_classes(p)
    if classes is not None:  # boxes that surely support each other, drawn as one
        merged = sample_worlds(quotient_probabilities(p, classes), worlds, seed=seed, thin=thin, burn_in=burn_in,
                               tries=tries)  # fmt: skip
        return spread_pairs(merged, classes, 1.0).astype(bool)
    n = p.shape[0]
    draws = np.zeros((worlds, n, n), dtype=bool)
    with _Chains(p, chains=1, seed=seed, burn_in=burn_in, tries=tries) as state:
        for k in range(worlds):
            state.advance(thin)
            draws[k] = unpack(state.successors[0], n, wide=state.wide)
    return draws
