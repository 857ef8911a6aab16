"""How a stack of problems and its results are laid out for the compiled loops.

``Jobs`` (one row per problem, operators of one order ``N``):

* ``ints (J, 6)``: the columns :data:`FORM` (0: undamped ``s = omega^2``, 1: first order
  ``lambda``), :data:`AFFINE` (1: ``A = a0 + p a1``), :data:`KEY` (the provider's key, -1: none),
  :data:`N_SCAN`, :data:`CHUNK` (scan points classified per call), :data:`LARGEST` (largest
  decoupled block);
* ``span (J, 2)``: ``p_min, p_max``; ``grids (J, G)``: the scan grid (``N_SCAN + 1`` points);
* ``a0, a1 (J, N, N)``; ``order, starts, nblocks, mirror, fixed``: the decoupled blocks, the
  signed copies among them and the eigenvalues of those the load does not change
  (:class:`impstab.linear.blocks.BlockStructure`); ``weights (J, n_dof)``: participation weights.

Results:

* ``onsets (J, C, 7)``: per bracket the columns :data:`LOAD`, :data:`KIND` (1 flutter,
  2 divergence, 3 a limit point still to be located), :data:`OMEGA`, :data:`DIRECTION` (+1 loss,
  -1 gain), :data:`WARNED` (1: located on the classification only), :data:`LO`, :data:`HI` (the
  bracket: stable end, unstable end);
* ``counts (J, 8)``: :data:`FIRST` (the bracket of the first loss, -1: none), :data:`EVALUATIONS`
  (eigenproblems solved), :data:`BISECTIONS`, :data:`BRACKETS`, :data:`STATUS` (1: the provider
  raised), :data:`START_UNSTABLE` (1: unstable at ``p_min``; its onset values in row 0), and
  among the eigenproblems :data:`DECOMPOSITIONS` (with eigenvectors) and :data:`PAIRS` (right
  and left vectors of two eigenvalues, by inverse iteration);
* ``mode (J, n_dof)`` complex and ``part (J, n_dof)``: mode and participation of the first loss.
"""

from collections import namedtuple

__all__ = ["Jobs"]

Jobs = namedtuple("Jobs", "ints span grids a0 a1 order starts nblocks mirror fixed weights")

FORM, AFFINE, KEY, N_SCAN, CHUNK, LARGEST = 0, 1, 2, 3, 4, 5
LOAD, KIND, OMEGA, DIRECTION, WARNED, LO, HI = 0, 1, 2, 3, 4, 5, 6
FIRST, EVALUATIONS, BISECTIONS, BRACKETS, STATUS, START_UNSTABLE, DECOMPOSITIONS, PAIRS = 0, 1, 2, 3, 4, 5, 6, 7
