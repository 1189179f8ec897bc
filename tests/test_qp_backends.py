"""QP backends: the dispatcher, agreement with quadprog, and every branch of each backend."""

from __future__ import annotations

import importlib
import re
import types
from collections.abc import Callable
from pathlib import Path
from typing import Any

import numpy as np
import pytest
import qpsolvers
from test_qp import feasible

import rrc_pin.solvers.qp_backends.daqp_backend as daqp_backend
import rrc_pin.solvers.qp_backends.osqp_backend as osqp_backend
import rrc_pin.solvers.qp_backends.qpsolvers_backend as qpsolvers_backend
from rrc_pin.solvers.errors import InvalidInput, ProblemError, UnknownBackend
from rrc_pin.solvers.qp_backends import (
    NATIVE,
    DaqpBackend,
    OSQPBackend,
    QpsolversBackend,
    installed_backends,
    make_backend,
)
from rrc_pin.solvers.qp_backends.qp import QP

MODULES = {"daqp": "daqp", "osqp": "osqp", "clarabel": "clarabel", "proxqp": "proxsuite",
           "quadprog": "quadprog"}  # fmt: skip
TOL = {"daqp": 1e-9, "osqp": 1e-6, "clarabel": 1e-7, "proxqp": 1e-6, "quadprog": 1e-9}
"""Agreement with quadprog, relative to 1 + |x|: the exact active-set solvers to 1e-9, the
others to their stated tolerances."""


def box_and_rows(rng: np.random.Generator, nz: int = 4, nc: int = 3, key: str = "") -> QP:
    """A feasible strictly convex QP with a box and two-sided rows (some sides infinite)."""
    A = rng.standard_normal((nz, nz))
    P = A @ A.T + 0.1 * np.eye(nz)
    q = rng.standard_normal(nz) * 3.0
    C = rng.standard_normal((nc, nz))
    z0 = rng.uniform(-0.5, 0.5, nz)  # feasible
    l, u = C @ z0 - rng.uniform(0.0, 1.0, nc), C @ z0 + rng.uniform(0.0, 1.0, nc)  # noqa: E741
    l[rng.random(nc) < 0.25] = -np.inf
    u[rng.random(nc) < 0.25] = np.inf
    lb, ub = z0 - rng.uniform(0.0, 1.0, nz), z0 + rng.uniform(0.0, 1.0, nz)
    return QP(P, q, C, l, u, lb, ub, key or f"box_rows:{nz}:{nc}")


def quadprog_x(qp: QP) -> np.ndarray:
    sol = qpsolvers.solve_problem(qp.problem(), solver="quadprog")
    assert sol.found
    return np.asarray(sol.x)


INFEASIBLE = QP(np.eye(2), np.zeros(2), np.array([[1.0, 1.0]]), np.array([3.0]),
                np.array([np.inf]), np.zeros(2), np.ones(2), "infeasible")  # fmt: skip
"""z1 + z2 >= 3 with 0 <= z <= 1."""


# -- the dispatcher -----------------------------------------------------------------------


def test_installed_backends_lists_daqp_and_osqp_first() -> None:
    names = installed_backends()
    assert names[:2] == ["daqp", "osqp"]
    assert names[2:] == sorted(names[2:])
    assert len(set(names)) == len(names)
    assert set(qpsolvers.available_solvers) <= set(names)
    for name in MODULES:  # CI installs all five
        assert name in names
    assert set(NATIVE) == {"daqp", "osqp"}


@pytest.mark.parametrize("name", ["gurobi-not-installed", "DAQP", "", None, 3])
def test_unknown_backend_lists_the_installed_ones(name: object) -> None:
    with pytest.raises(UnknownBackend) as info:
        make_backend(name)  # type: ignore[arg-type]
    assert info.value.backend == str(name)
    assert info.value.available == installed_backends()
    assert all(n in str(info.value) for n in installed_backends())
    assert "pip install" in str(info.value)
    assert isinstance(info.value, ValueError)


@pytest.mark.parametrize(
    ("name", "options"),
    [("daqp", {"iter_limt": 100}),
     ("osqp", {"max_iters": 100}),
     ("quadprog", {"factorised": True}),
     ("proxqp", {"eps_abss": 1e-9}),
     ("clarabel", {"max_iters": 100})],
)  # fmt: skip
def test_misspelt_options_are_refused_at_construction(name: str, options: dict) -> None:
    pytest.importorskip(MODULES[name])
    with pytest.raises(InvalidInput) as info:
        make_backend(name, **options)
    assert info.value.argument == "backend_options"
    assert name in str(info.value) and next(iter(options)) in str(info.value)
    assert isinstance(info.value.__cause__, ProblemError)


@pytest.mark.parametrize(
    ("name", "options"),
    [("daqp", {"iter_limit": 100}),
     ("osqp", {"max_iter": 5000, "eps_abs": 1e-6}),
     ("quadprog", {}),
     ("proxqp", {"max_iter": 500}),
     ("clarabel", {"max_iter": 50})],
)  # fmt: skip
def test_valid_options_are_kept_and_the_backend_starts_cold(name: str, options: dict) -> None:
    pytest.importorskip(MODULES[name])
    backend = make_backend(name, **options)
    assert backend.name == name
    assert {k: backend.options[k] for k in options} == options
    assert backend.warm_start_state() == {}  # the probe's solution is forgotten


def test_options_that_fail_the_probe_are_refused() -> None:
    """Accepted settings that cannot solve the probe QP (one iteration) are refused too."""
    with pytest.raises(InvalidInput, match="fails a 2-variable QP") as info:
        make_backend("osqp", max_iter=1, polishing=False)
    assert info.value.argument == "backend_options"


# -- agreement -----------------------------------------------------------------------------


@pytest.fixture(scope="module")
def reference() -> list[tuple[QP, np.ndarray]]:
    pytest.importorskip("quadprog")
    rng = np.random.default_rng(5)
    out = []
    for k in range(60):
        nz, nc = 2 + k % 5, k % 4
        qp = box_and_rows(rng, nz, nc)
        if nc == 0:
            qp = qp._replace(C=None, l=None, u=None, key=f"box:{nz}")
        out.append((qp, quadprog_x(qp)))
    return out


@pytest.mark.parametrize("name", sorted(MODULES))
def test_every_backend_agrees_with_quadprog(
    name: str, reference: list[tuple[QP, np.ndarray]]
) -> None:
    pytest.importorskip(MODULES[name])
    backend = make_backend(name)
    worst = 0.0
    for qp, x_ref in reference:
        for _ in range(2):  # cold, then warm-started from the same problem
            sol = backend.solve(qp)
            assert sol.x is not None, (name, qp.key, sol.status)
            assert sol.status == "solved" and sol.backend == name
            assert sol.solve_time > 0.0 and sol.iterations >= 0
            assert feasible(qp, sol.x, tol=10.0 * TOL[name])
            worst = max(worst, float(np.abs(sol.x - x_ref).max() / (1.0 + np.abs(x_ref).max())))
    assert worst < TOL[name], worst


@pytest.mark.parametrize("name", sorted(MODULES))
def test_a_key_reused_for_another_size_still_gives_the_right_answer(
    name: str, rng: np.random.Generator
) -> None:
    """A caller's key collision must not leave a stale warm start or workspace in place."""
    pytest.importorskip(MODULES[name])
    backend = make_backend(name)
    for nz, nc in ((3, 2), (5, 4), (2, 1), (5, 4)):
        qp = box_and_rows(rng, nz, nc, key="same")
        sol = backend.solve(qp)
        assert sol.x is not None and sol.x.shape == (nz,), (name, nz, sol.status)
        np.testing.assert_allclose(sol.x, quadprog_x(qp), atol=10.0 * TOL[name])


@pytest.mark.parametrize("name", sorted(MODULES))
def test_warm_start_state_returns_copies(name: str, rng: np.random.Generator) -> None:
    pytest.importorskip(MODULES[name])
    backend = make_backend(name)
    a, b = box_and_rows(rng, 3, 2, key="a"), box_and_rows(rng, 4, 1, key="b")
    xa, xb = backend.solve(a).x, backend.solve(b).x
    state = backend.warm_start_state()
    assert set(state) == {"a", "b"}
    np.testing.assert_array_equal(state["a"], xa)
    np.testing.assert_array_equal(state["b"], xb)
    state["a"][:] = 1e6
    state["b"] = np.zeros(4)
    np.testing.assert_array_equal(backend.warm_start_state()["a"], xa)
    np.testing.assert_array_equal(backend.warm_start_state()["b"], xb)
    backend.reset()
    assert backend.warm_start_state() == {}


@pytest.mark.parametrize("name", sorted(MODULES))
def test_an_unsolvable_qp_returns_no_solution(name: str) -> None:
    pytest.importorskip(MODULES[name])
    backend = make_backend(name)
    sol = backend.solve(INFEASIBLE)
    assert sol.x is None and sol.status != "solved" and sol.backend == name
    assert "infeasible" not in backend.warm_start_state()


def test_every_backend_module_names_algorithm_reference_and_warm_start() -> None:
    for module in (daqp_backend, osqp_backend, qpsolvers_backend):
        doc = importlib.import_module(module.__name__).__doc__ or ""
        assert "Algorithm" in doc, module.__name__
        assert re.search(r"(19|20)\d\d", doc), module.__name__  # a dated reference
        assert re.search(r"warm.start", doc, re.IGNORECASE), module.__name__
    assert "Arnström" in (daqp_backend.__doc__ or "")
    assert "Stellato" in (osqp_backend.__doc__ or "")
    doc = qpsolvers_backend.__doc__ or ""
    assert "Goldfarb" in doc and "Bambade" in doc and "Goulart" in doc


# -- OSQP: every branch, through OSQP's public API ------------------------------------------


@pytest.fixture
def osqp_calls(monkeypatch: pytest.MonkeyPatch) -> list[tuple[str, tuple, dict, Any]]:
    """Every call the backend makes to ``osqp.OSQP``: (method, args, kwargs, result)."""
    osqp = pytest.importorskip("osqp")
    calls: list[tuple[str, tuple, dict, Any]] = []
    for method in ("setup", "update", "warm_start", "solve"):
        original = getattr(osqp.OSQP, method)

        def spy(self: Any, *args: Any, _original: Callable = original, _method: str = method,
                **kwargs: Any) -> Any:  # fmt: skip
            result = _original(self, *args, **kwargs)
            calls.append((_method, args, kwargs, result))
            return result

        monkeypatch.setattr(osqp.OSQP, method, spy)
    return calls


def names(calls: list[tuple[str, tuple, dict, Any]]) -> list[str]:
    return [c[0] for c in calls]


def fail_first_solves(monkeypatch: pytest.MonkeyPatch, count: int, result: Any) -> None:
    """The next ``count`` OSQP solves return ``result`` (after running, so the state moves)."""
    import osqp

    original = osqp.OSQP.solve
    left = [count]

    def solve(self: Any, *args: Any, **kwargs: Any) -> Any:
        real = original(self, *args, **kwargs)
        if left[0] > 0:
            left[0] -= 1
            return result
        return real

    monkeypatch.setattr(osqp.OSQP, "solve", solve)


def fake(status: str, iterations: int, x: Any = None) -> types.SimpleNamespace:
    return types.SimpleNamespace(x=x, info=types.SimpleNamespace(status=status, iter=iterations))


def test_osqp_sets_up_once_per_key_then_updates(osqp_calls: list, rng: np.random.Generator) -> None:
    backend = OSQPBackend()
    first, second = box_and_rows(rng), box_and_rows(rng)  # one structure, other numbers
    sol = backend.solve(first)
    assert names(osqp_calls).count("setup") == 1 and "update" not in names(osqp_calls)
    np.testing.assert_allclose(sol.x, quadprog_x(first), atol=1e-7)
    osqp_calls.clear()
    sol = backend.solve(second)
    assert names(osqp_calls) == ["update", "solve"]  # warm: no setup, no reset of x, y
    update = osqp_calls[0][2]
    assert set(update) == {"q", "l", "u", "Px", "Ax"}
    np.testing.assert_array_equal(update["q"], second.q)
    np.testing.assert_array_equal(update["l"], np.concatenate([second.lb, second.l]))
    np.testing.assert_array_equal(update["u"], np.concatenate([second.ub, second.u]))
    nz, nc = second.q.size, second.C.shape[0]  # type: ignore[union-attr]
    assert update["Px"].size == nz * (nz + 1) // 2  # the dense upper triangle
    assert update["Ax"].size == (nz + nc) * nz  # identity rows (the box) above C, dense
    np.testing.assert_allclose(sol.x, quadprog_x(second), atol=1e-7)  # the new data solved
    osqp_calls.clear()
    backend.solve(box_and_rows(rng, 3, 1))  # another structure: a second workspace
    assert names(osqp_calls).count("setup") == 1


def test_osqp_warm_start_carries_and_reset_starts_cold(
    osqp_calls: list, rng: np.random.Generator
) -> None:
    qp = box_and_rows(rng, 6, 4)
    cold = OSQPBackend().solve(qp).iterations
    backend = OSQPBackend()
    assert backend.solve(qp).iterations == cold
    warm = backend.solve(qp)
    assert warm.iterations < cold  # from the previous solution
    np.testing.assert_allclose(backend.warm_start_state()[qp.key], warm.x)
    backend.reset()
    assert backend.warm_start_state() == {}
    osqp_calls.clear()
    again = backend.solve(qp)
    assert names(osqp_calls) == ["update", "warm_start", "solve"]  # no new setup
    start = osqp_calls[1][2]
    assert not start["x"].any() and not start["y"].any()  # from zero
    assert start["x"].size == 6 and start["y"].size == 6 + 4
    assert again.iterations == cold
    osqp_calls.clear()
    backend.solve(qp)  # solved: warm again
    assert names(osqp_calls) == ["update", "solve"]


def test_osqp_retries_a_failed_warm_start_from_zero(
    osqp_calls: list, monkeypatch: pytest.MonkeyPatch, rng: np.random.Generator
) -> None:
    qp = box_and_rows(rng, 5, 3)
    backend = OSQPBackend()
    backend.solve(qp)  # warm from here on
    fail_first_solves(monkeypatch, 1, fake("maximum iterations reached", 17))
    osqp_calls.clear()
    sol = backend.solve(qp)
    assert names(osqp_calls) == ["update", "solve", "warm_start", "solve"]
    start = osqp_calls[2][2]
    assert not start["x"].any() and not start["y"].any()
    retry = osqp_calls[3][3]
    assert sol.iterations == 17 + retry.info.iter  # both attempts counted
    assert sol.status == "solved"
    np.testing.assert_allclose(sol.x, quadprog_x(qp), atol=1e-7)


def test_osqp_retry_after_a_very_different_problem(osqp_calls: list) -> None:
    """A warm start from a distant solution, with few iterations: the retry happens."""
    nz = 6
    P = np.eye(nz)
    C = np.ones((1, nz))
    near = QP(P, np.full(nz, -0.1), C, np.array([-1.0]), np.array([1.0]), -np.ones(nz),
              np.ones(nz), "k")  # fmt: skip
    far = near._replace(q=np.full(nz, 50.0), l=np.array([-5.0]), u=np.array([-4.0]))
    backend = OSQPBackend(max_iter=10, polishing=False)
    assert backend.solve(near).status == "solved"  # no active row: solved in 10 iterations
    osqp_calls.clear()
    sol = backend.solve(far)
    solves = [c[3] for c in osqp_calls if c[0] == "solve"]
    assert names(osqp_calls) == ["update", "solve", "warm_start", "solve"]
    assert solves[0].info.status == "maximum iterations reached"
    assert sol.iterations == sum(r.info.iter for r in solves) == 20
    assert sol.x is None and sol.status == solves[1].info.status


def test_osqp_failed_cold_solve_is_not_retried(osqp_calls: list) -> None:
    backend = OSQPBackend()
    sol = backend.solve(INFEASIBLE)  # a new workspace: it starts from zero already
    assert sol.x is None and sol.status == "primal infeasible"
    assert names(osqp_calls).count("solve") == 1
    assert sol.iterations == osqp_calls[-1][3].info.iter
    osqp_calls.clear()
    again = backend.solve(INFEASIBLE)  # after a failure: cold, and not retried
    assert names(osqp_calls) == ["update", "warm_start", "solve"]
    assert again.x is None and again.status == "primal infeasible"


def test_osqp_failure_returns_osqps_status(rng: np.random.Generator) -> None:
    backend = OSQPBackend(max_iter=3, polishing=False)
    sol = backend.solve(box_and_rows(rng, 6, 4))
    assert sol.x is None and sol.status == "maximum iterations reached" and sol.iterations == 3
    assert backend.warm_start_state() == {}


def test_osqp_accepts_a_solved_inaccurate_answer(
    monkeypatch: pytest.MonkeyPatch, rng: np.random.Generator
) -> None:
    qp = box_and_rows(rng)
    backend = OSQPBackend()
    x = np.array([0.1, 0.2, 0.3, 0.4])
    fail_first_solves(monkeypatch, 1, fake("solved inaccurate", 40, x))
    sol = backend.solve(qp)
    assert sol.status == "solved" and sol.iterations == 40
    np.testing.assert_array_equal(sol.x, x)
    assert sol.x is not x  # a copy
    np.testing.assert_array_equal(backend.warm_start_state()[qp.key], x)


def test_osqp_non_finite_solution_is_no_solution(
    osqp_calls: list, monkeypatch: pytest.MonkeyPatch, rng: np.random.Generator
) -> None:
    qp = box_and_rows(rng)
    backend = OSQPBackend()
    backend.solve(qp)
    fail_first_solves(monkeypatch, 2, fake("solved", 5, np.array([0.0, np.nan, 0.0, 0.0])))
    sol = backend.solve(qp)
    assert sol.x is None and sol.status == "non-finite solution"
    assert qp.key not in backend.warm_start_state()
    osqp_calls.clear()
    backend.solve(qp)  # cold after the failure
    assert "warm_start" in names(osqp_calls)


def test_osqp_exception_becomes_problem_error_and_drops_the_workspace(
    osqp_calls: list, monkeypatch: pytest.MonkeyPatch, rng: np.random.Generator
) -> None:
    import osqp

    qp = box_and_rows(rng)
    backend = OSQPBackend()
    backend.solve(qp)

    def explode(self: Any, **kwargs: Any) -> None:
        raise RuntimeError("solver crashed")

    with monkeypatch.context() as patch:
        patch.setattr(osqp.OSQP, "update", explode)
        with pytest.raises(ProblemError, match="^osqp: solver crashed") as info:
            backend.solve(qp)
    assert isinstance(info.value.__cause__, RuntimeError)
    osqp_calls.clear()
    sol = backend.solve(qp)  # the workspace was dropped: set up again
    assert names(osqp_calls)[0] == "setup" and sol.status == "solved"


def test_osqp_setup_error_is_a_problem_error(osqp_calls: list, rng: np.random.Generator) -> None:
    backend = OSQPBackend(max_iters=10)  # unchecked here: make_backend checks it
    qp = box_and_rows(rng)
    for _ in range(2):  # no workspace is kept: the setup is tried again
        with pytest.raises(ProblemError, match="^osqp:"):
            backend.solve(qp)
    assert names(osqp_calls) == []  # setup raised both times, nothing recorded after it


def test_osqp_defaults() -> None:
    s = osqp_backend.DEFAULT_SETTINGS
    assert s["eps_abs"] <= 1e-6 and s["eps_rel"] <= 1e-6 and s["polishing"]
    assert s["max_iter"] >= 20000 and s["warm_starting"] and not s["verbose"]
    assert "scaling" not in s  # Ruiz scaling left on (issue 18: off, it froze arms)
    assert OSQPBackend(eps_abs=1e-5).options["eps_abs"] == 1e-5
    assert osqp_backend.ACCEPTED == ("solved", "solved inaccurate")


# -- DAQP ------------------------------------------------------------------------------------


@pytest.fixture
def daqp_calls(monkeypatch: pytest.MonkeyPatch) -> list[dict]:
    daqp = pytest.importorskip("daqp")
    calls: list[dict] = []
    original = daqp.solve

    def spy(*args: Any, **kwargs: Any) -> Any:
        calls.append({"args": args, **kwargs})
        return original(*args, **kwargs)

    monkeypatch.setattr(daqp, "solve", spy)
    return calls


def test_daqp_warm_starts_per_key(daqp_calls: list[dict], rng: np.random.Generator) -> None:
    backend = DaqpBackend()
    a, b = box_and_rows(rng, 4, 3, key="a"), box_and_rows(rng, 3, 0, key="b")
    b = b._replace(C=None, l=None, u=None)
    xa = backend.solve(a).x
    assert daqp_calls[-1]["primal_start"] is None
    xb = backend.solve(b).x
    assert daqp_calls[-1]["primal_start"] is None  # another key: its own state
    sol = backend.solve(a)
    np.testing.assert_array_equal(daqp_calls[-1]["primal_start"], xa)
    np.testing.assert_allclose(sol.x, xa, atol=1e-12)
    state = backend.warm_start_state()
    np.testing.assert_array_equal(state["b"], xb)
    assert daqp_calls[-1]["primal_tol"] == 1e-9  # the default setting
    # the box first, then the rows of unit norm, two-sided, infinite sides as they are
    _, _, A, upper, lower, sense = daqp_calls[-1]["args"]
    norms = np.linalg.norm(a.C, axis=1)
    np.testing.assert_allclose(A, a.C / norms[:, None], rtol=1e-15)
    np.testing.assert_allclose(upper, np.concatenate([a.ub, a.u / norms]), rtol=1e-15)
    np.testing.assert_allclose(lower, np.concatenate([a.lb, a.l / norms]), rtol=1e-15)
    assert sense.dtype == np.intc and not sense.any()


def test_daqp_failure_returns_the_exitflag(
    daqp_calls: list[dict], rng: np.random.Generator
) -> None:
    backend = DaqpBackend()
    qp = box_and_rows(rng, 2, 1, key="infeasible")
    assert backend.solve(qp).x is not None
    sol = backend.solve(INFEASIBLE)  # same key, now infeasible: the state is dropped
    assert sol.x is None and re.fullmatch(r"exitflag -?\d+", sol.status)
    assert int(sol.status.split()[1]) < 0
    assert "infeasible" not in backend.warm_start_state()
    backend.solve(INFEASIBLE)
    assert daqp_calls[-1]["primal_start"] is None


def test_daqp_retries_a_declared_infeasible_problem_once_at_a_looser_tolerance(
    monkeypatch: pytest.MonkeyPatch, rng: np.random.Generator
) -> None:
    """DAQP calls some feasible degenerate problems infeasible at 1e-9 (daqp_backend.RETRY_TOL):
    one cold retry at 1e-8 answers them, its iterations counted; a truly infeasible problem
    is tried twice and reported; a tolerance already that loose is not retried."""
    import daqp

    calls: list[dict] = []
    original = daqp.solve

    def first_call_infeasible(*args: Any, **kwargs: Any) -> Any:
        calls.append(kwargs)
        x, fval, exitflag, info = original(*args, **kwargs)
        if len(calls) == 1:
            return x, fval, -1, {**info, "iterations": 7}
        return x, fval, exitflag, info

    monkeypatch.setattr(daqp, "solve", first_call_infeasible)
    qp = box_and_rows(rng, 4, 3, key="degenerate")
    sol = DaqpBackend().solve(qp)
    assert sol.x is not None and sol.status == "solved" and feasible(qp, sol.x, 1e-8)
    assert [c["primal_tol"] for c in calls] == [1e-9, daqp_backend.RETRY_TOL]
    assert calls[1]["primal_start"] is None and sol.iterations >= 7
    calls.clear()
    assert DaqpBackend().solve(INFEASIBLE).x is None
    assert len(calls) == 2  # the first call made to fail, then the real retry
    calls.clear()
    assert DaqpBackend(primal_tol=1e-6).solve(INFEASIBLE).x is None and len(calls) == 1


@pytest.mark.parametrize("tick", [1710, 21920])
def test_daqp_retries_a_cycling_problem_cold_at_a_looser_tolerance(tick: int) -> None:
    """Direction QPs of 10-minute panda-folding sessions (collision rows of near-parallel
    capsules): DAQP cycles on them at 1e-9 (exit flag -2, warm or cold); the backend's cold
    retry at CYCLING_TOL solves them."""
    import daqp

    data = np.load(Path(__file__).parent / "data" / "daqp_cycling.npz")
    P, q, C, lo, hi, lb, ub = (data[f"{k}_{tick}"] for k in ("P", "q", "C", "l", "u", "lb", "ub"))
    qp = QP(P, q, C, lo, hi, lb, ub, f"direction:{tick}")
    norms = np.linalg.norm(qp.C, axis=1)
    upper = np.concatenate([qp.ub, qp.u / norms])
    lower = np.concatenate([qp.lb, qp.l / norms])
    sense = np.zeros(upper.size, dtype=np.intc)
    assert daqp.solve(qp.P, qp.q, qp.C / norms[:, None], upper, lower, sense,
                      primal_tol=1e-9)[2] == -2  # fmt: skip
    sol = DaqpBackend().solve(qp)
    assert sol.status == "solved" and feasible(qp, sol.x, daqp_backend.CYCLING_TOL)


def test_daqp_exception_becomes_problem_error() -> None:
    with pytest.raises(ProblemError, match="^daqp:") as info:
        DaqpBackend(iter_limt=5).solve(INFEASIBLE)
    assert isinstance(info.value.__cause__, TypeError)


# -- qpsolvers ---------------------------------------------------------------------------------


def test_qpsolvers_widens_zero_width_bounds() -> None:
    """quadprog fails on this QP with lb == ub on z3 (the two active rows of the fixed
    variable are dependent); widened by WIDTH, it solves it, as DAQP does."""
    pytest.importorskip("quadprog")
    P = np.array([[3.77, -3.34, -3.05, -0.22], [-3.34, 12.49, 2.28, 0.85],
                  [-3.05, 2.28, 8.72, 1.33], [-0.22, 0.85, 1.33, 0.39]])  # fmt: skip
    q = np.array([0.17, -0.26, 0.28, -7.14])
    lb, ub = np.array([-0.32, -0.48, -0.11, 0.1]), np.array([0.1, 0.14, 0.8, 0.1])
    qp = QP(P, q, None, None, None, lb, ub, "fixed")
    assert not qpsolvers.solve_problem(qp.problem(), solver="quadprog").found
    sol = QpsolversBackend("quadprog").solve(qp)
    assert sol.x is not None and sol.status == "solved"
    width = qpsolvers_backend.WIDTH
    assert 0.1 <= sol.x[3] <= 0.1 + width * 1.1 * (1.0 + 1e-12)
    exact = DaqpBackend().solve(qp).x
    np.testing.assert_allclose(sol.x, exact, atol=1e-8)


def test_qpsolvers_widens_zero_width_rows() -> None:
    """Rows with l == u become l <= C z <= l + WIDTH (1 + |l|); the box too; inf kept."""
    pytest.importorskip("quadprog")
    qp = QP(np.eye(3), np.array([-1.0, -1.0, -1.0]), np.array([[1.0, 1.0, 0.0]]),
            np.array([0.5]), np.array([0.5]), np.array([0.25, -1.0, 2.0]),
            np.array([0.25, 1.0, 2.0]), "fixed")  # fmt: skip
    sol = QpsolversBackend("quadprog").solve(qp)
    assert sol.x is not None
    width = qpsolvers_backend.WIDTH
    np.testing.assert_allclose(sol.x, [0.25, 0.25, 2.0], atol=4.0 * width)
    assert 0.5 - 1e-15 <= sol.x[0] + sol.x[1] <= 0.5 + width * 1.5 + 1e-15
    lo = np.array([1.0, -np.inf, 0.0, np.inf, -2.0])
    hi = np.array([1.0, 2.0, np.inf, np.inf, -2.0])
    want = [1.0 + width * 2.0, 2.0, np.inf, np.inf, -2.0 + width * 3.0]
    np.testing.assert_array_equal(qpsolvers_backend._widen(lo, hi), want)


def test_qpsolvers_passes_the_warm_start_as_initvals(
    monkeypatch: pytest.MonkeyPatch, rng: np.random.Generator
) -> None:
    calls: list[dict] = []
    original = qpsolvers.solve_problem

    def spy(problem: qpsolvers.Problem, **kwargs: Any) -> Any:
        calls.append(kwargs)
        return original(problem, **kwargs)

    monkeypatch.setattr(qpsolvers, "solve_problem", spy)
    backend = QpsolversBackend("clarabel")
    qp = box_and_rows(rng)
    first = backend.solve(qp)
    assert calls[-1]["initvals"] is None and calls[-1]["solver"] == "clarabel"
    assert calls[-1]["tol_feas"] == 1e-10  # the default options
    backend.solve(qp)
    np.testing.assert_array_equal(calls[-1]["initvals"], first.x)
    backend.reset()
    backend.solve(qp)
    assert calls[-1]["initvals"] is None


def test_qpsolvers_failures(monkeypatch: pytest.MonkeyPatch, rng: np.random.Generator) -> None:
    backend = QpsolversBackend("quadprog")
    qp = box_and_rows(rng)

    def explode(problem: qpsolvers.Problem, **kwargs: Any) -> None:
        raise RuntimeError("solver crashed")

    with monkeypatch.context() as patch:
        patch.setattr(qpsolvers, "solve_problem", explode)
        with pytest.raises(ProblemError, match="^quadprog: solver crashed") as info:
            backend.solve(qp)
        assert isinstance(info.value.__cause__, RuntimeError)

    def non_finite(problem: qpsolvers.Problem, **kwargs: Any) -> qpsolvers.Solution:
        sol = qpsolvers.Solution(problem)
        sol.found, sol.x = True, np.array([np.nan, 0.0, 0.0, 0.0])
        return sol

    with monkeypatch.context() as patch:
        patch.setattr(qpsolvers, "solve_problem", non_finite)
        sol = backend.solve(qp)
    assert sol.x is None and sol.status == "not found"
    assert backend.warm_start_state() == {}
    sol = backend.solve(INFEASIBLE)
    assert sol.x is None and sol.status == "not found" and sol.backend == "quadprog"


def test_qpsolvers_defaults() -> None:
    defaults = qpsolvers_backend.DEFAULT_OPTIONS
    assert defaults["proxqp"]["check_duality_gap"] is True
    assert QpsolversBackend("proxqp", eps_abs=1e-7).options["eps_abs"] == 1e-7
    assert QpsolversBackend("quadprog").options == {}
    assert QpsolversBackend("clarabel").name == "clarabel"


# -- malformed answers of the solver libraries ----------------------------------------------

MALFORMED = [None, "x", [0.1, [0.2]], np.array(["a"] * 4), np.zeros(4, complex),
             np.ones(4, bool), np.zeros(3), np.zeros((4, 1)), np.full(4, np.inf), {},
             object()]  # fmt: skip
"""What a solver library might hand back as its solution x: never an answer."""


@pytest.mark.parametrize("x", MALFORMED, ids=lambda x: type(x).__name__)
def test_a_malformed_solution_from_any_library_is_no_answer(
    x: Any, monkeypatch: pytest.MonkeyPatch, rng: np.random.Generator
) -> None:
    """Each library patched to return ``x`` as its solution (status solved), or to return
    None or a foreign object instead of its result: the backend answers no solution or
    raises ProblemError, nothing else (an AttributeError escaped before)."""
    import daqp

    qp = box_and_rows(rng)
    for returned in ((x, 0.0, 1, {"iterations": 1}), None, 3.5):
        monkeypatch.setattr(daqp, "solve", lambda *a, r=returned, **k: r)
        outcome(DaqpBackend(), qp)

    def qpsolvers_answer(problem: qpsolvers.Problem, **kwargs: Any) -> Any:
        sol = qpsolvers.Solution(problem)
        sol.found, sol.x = True, x
        return sol

    for fake in (qpsolvers_answer, lambda *a, **k: None, lambda *a, **k: "solved"):
        monkeypatch.setattr(qpsolvers, "solve_problem", fake)
        outcome(QpsolversBackend("quadprog"), qp)

    for result in (fake("solved", 3, x), None, "solved"):
        with monkeypatch.context() as patch:
            fail_first_solves(patch, 1, result)
            outcome(OSQPBackend(), qp)


def outcome(backend: Any, qp: QP) -> None:
    """The backend's answer to ``qp``: no solution, or a ProblemError; nothing else."""
    try:
        sol = backend.solve(qp)
    except ProblemError:
        return
    assert sol.x is None, sol
