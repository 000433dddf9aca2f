"""A black-box log-likelihood, vectorised over particles, as a PyTensor Op.

The expensive part of the study is simulating the harvester for a parameter vector and comparing
the simulated relative acceleration with the measured one. That simulation is written in NumPy or
Numba and is fastest when it gets all particles of a TMCMC stage at once, so the Op wraps a callable

    fn(theta: ndarray[N, P]) -> ndarray[N]      (log-likelihood of each row)

Core form and batching
----------------------
`BatchedLogLike` has the gufunc signature ``(p)->()``: its core form maps one parameter vector
``theta`` (P,) to a scalar log-likelihood. The Op itself is batch-capable, like an ``Elemwise``:
``make_node`` accepts any number of leading batch dimensions, and ``perform`` flattens them into
rows and calls ``fn`` ONCE on the (N, P) matrix. It is registered with
``pytensor.graph.replace._vectorize_node`` so that ``vectorize_graph`` re-applies the same Op to the
batched input, instead of the default fallback, which wraps an Op in a ``Blockwise`` that loops
over the batch in Python (one ``fn`` call per particle).

Where the likelihood goes in a PyMC model
-----------------------------------------
PyMC's SMC (and our `harvester.inference.tmcmc.TMCMC`) tempers only ``model.datalogp``; ``model.varlogp``
is the prior. ``model.datalogp = model.observedlogp + model.potentiallogp`` (pymc 5.28,
``pymc/model/core.py``), so both a ``pm.Potential`` and an observed ``pm.CustomDist`` are tempered.
`loglike_potential` uses the observed ``pm.CustomDist`` by default: the term is then an observed
variable, with a name in ``model.observed_RVs``, and PyMC does not warn that Potentials are ignored
by forward sampling. ``as_potential=True`` gives the ``pm.Potential`` form instead.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence

import numpy as np
import pymc as pm
import pytensor.tensor as pt
from pytensor.graph.basic import Apply
from pytensor.graph.op import Op
from pytensor.graph.replace import _vectorize_node
from pytensor.tensor.variable import TensorVariable

__all__ = ["BatchedLogLike", "loglike_potential", "parameter_vector"]

LogLikeFn = Callable[[np.ndarray], np.ndarray]


class BatchedLogLike(Op):
    """Log-likelihood ``fn(theta[N, P]) -> [N]`` of a black-box model, one call per batch.

    Parameters
    ----------
    fn
        Vectorised log-likelihood: takes an (N, P) float64 array, one parameter vector per row,
        and returns N log-likelihoods. It may return ``-inf`` (parameters the model cannot
        simulate); ``NaN`` is mapped to ``-inf`` so that a sampler rejects the point.
    n_params
        P, the length of the core parameter vector.
    name
        Shown when the graph is printed.

    Notes
    -----
    No gradient: use gradient-free samplers (TMCMC, SMC, Metropolis). ``fn`` must be picklable
    by ``cloudpickle`` if chains are run in parallel processes. Two instances are equal only if
    they are the same object (no ``__props__``), so ``fn`` need not be hashable and PyTensor
    never merges likelihoods built from different callables.
    """

    gufunc_signature = "(p)->()"

    def __init__(self, fn: LogLikeFn, n_params: int, name: str | None = None) -> None:
        if not callable(fn):
            raise TypeError(f"fn must be callable, got {type(fn).__name__}")
        if int(n_params) < 1:
            raise ValueError(f"n_params must be a positive integer, got {n_params}")
        self.fn = fn
        self.n_params = int(n_params)
        self.name = name or getattr(fn, "__name__", "loglike")
        super().__init__()

    def __str__(self) -> str:
        return f"BatchedLogLike{{{self.name}, {self.gufunc_signature}}}"

    def make_node(self, theta) -> Apply:
        theta = pt.as_tensor_variable(theta)
        if theta.type.ndim < 1:
            raise ValueError(f"{self}: theta must have at least one dimension (p), got a scalar")
        core_length = theta.type.shape[-1]
        if core_length is not None and core_length != self.n_params:
            raise ValueError(
                f"{self}: theta has {core_length} parameters in its last axis, "
                f"the Op was built for {self.n_params}"
            )
        theta = pt.cast(theta, "float64")
        out = pt.tensor(dtype="float64", shape=theta.type.shape[:-1])
        return Apply(self, [theta], [out])

    def perform(self, node, inputs, output_storage) -> None:
        (theta,) = inputs
        batch_shape = theta.shape[:-1]
        rows = np.ascontiguousarray(theta, dtype=np.float64).reshape(-1, self.n_params)
        loglike = np.array(self.fn(rows), dtype=np.float64).reshape(-1)
        if loglike.shape[0] != rows.shape[0]:
            raise ValueError(
                f"{self}: fn returned {loglike.shape[0]} log-likelihoods for {rows.shape[0]} "
                "parameter vectors; it must return one per row"
            )
        loglike[np.isnan(loglike)] = -np.inf
        output_storage[0][0] = loglike.reshape(batch_shape)

    def infer_shape(self, fgraph, node, input_shapes):
        return [tuple(input_shapes[0][:-1])]

    def grad(self, inputs, output_grads):
        raise NotImplementedError(
            f"{self} has no gradient: the black-box likelihood is not differentiable in PyTensor. "
            "Sample with a gradient-free method (harvester.inference.tmcmc.TMCMC, pm.sample_smc, "
            "pm.Metropolis), not NUTS."
        )


@_vectorize_node.register(BatchedLogLike)
def _vectorize_batched_loglike(op: BatchedLogLike, node: Apply, batched_theta) -> Apply:
    """The Op already broadcasts over leading dimensions: re-apply it, no Blockwise loop."""
    return op.make_node(batched_theta)


def parameter_vector(params: Sequence[TensorVariable]) -> TensorVariable:
    """Ravel and concatenate ``params`` into one vector theta, in the order given."""
    if not params:
        raise ValueError("params is empty: the likelihood needs at least one parameter")
    pieces = [pt.atleast_1d(pt.as_tensor_variable(p)).ravel() for p in params]
    return pieces[0] if len(pieces) == 1 else pt.concatenate(pieces)


def _static_length(theta: TensorVariable, params: Sequence[TensorVariable]) -> int:
    (length,) = theta.type.shape
    if length is None:
        names = [getattr(p, "name", None) or str(p) for p in params]
        raise ValueError(
            f"the sizes of params {names} are not known when the graph is built; "
            "give the model variables a fixed shape (e.g. shape=3)"
        )
    return int(length)


def loglike_potential(
    name: str,
    fn: LogLikeFn,
    params: Sequence[TensorVariable],
    *,
    as_potential: bool = False,
    model: pm.Model | None = None,
) -> TensorVariable:
    """Add the black-box log-likelihood ``fn`` to a PyMC model so that it counts in ``datalogp``.

    Parameters
    ----------
    name
        Name of the model term.
    fn
        Vectorised log-likelihood ``fn(theta[N, P]) -> [N]``; theta's columns are ``params``
        raveled and concatenated in the order given.
    params
        Model variables (free RVs or expressions of them) the likelihood depends on.
    as_potential
        False (default): an observed ``pm.CustomDist`` with signature ``(p)->()`` whose logp is
        the Op and whose observed value is a dummy 0.0 that the logp ignores.
        True: ``pm.Potential(name, op(theta))``. Both land in ``model.datalogp``, which SMC
        tempers; only the CustomDist form is an observed variable (shown in ``observed_data``
        and usable for ``pm.compute_log_likelihood``).
    model
        Model to add to; defaults to the model in context.

    Returns
    -------
    The observed variable (or the Potential).
    """
    model = pm.modelcontext(model)
    theta = parameter_vector(params)
    op = BatchedLogLike(fn, _static_length(theta, params), name=name)
    with model:
        if as_potential:
            return pm.Potential(name, op(theta))

        def logp(value, theta):
            # The observed value is a placeholder: the data live inside fn.
            return op(theta)

        return pm.CustomDist(
            name,
            theta,
            logp=logp,
            signature="(p)->()",
            observed=np.array(0.0),
            dtype="float64",
        )
