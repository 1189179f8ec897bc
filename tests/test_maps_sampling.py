"""Fixed blocks and seeds: a block's samples depend on (seed, block) only."""

from __future__ import annotations

import numpy as np

import rrc_pin
from rrc_pin.maps.kinematics import chain_of
from rrc_pin.solvers.maps.sampling import BLOCK, Plan, block_samples, block_stream, sample_at


def test_plan_blocks_and_tasks():
    plan = Plan(5 * BLOCK + 7)
    assert plan.blocks == 6 and plan.length(5) == 7 and plan.length(0) == BLOCK
    assert plan.first(3) == 3 * BLOCK
    assert plan.tasks([0, 1, 2, 3, 4], 2) == [[0, 1], [2, 3], [4]]
    assert plan.tasks([5, 0, 1, 3], 8) == [[0, 1], [3], [5]]  # a gap starts a new task
    assert Plan(1).blocks == 1 and Plan(1).length(0) == 1


def test_a_blocks_samples_depend_on_seed_and_block_only():
    chain, _ = chain_of(rrc_pin.load("kinova"))  # continuous joints: [-pi, pi]
    a = block_samples(chain, 7, Plan(10 * 256, 256), 3)
    b = block_samples(chain, 7, Plan(4 * 256, 256), 3)  # another map size, same block
    assert np.array_equal(a, b)
    assert not np.array_equal(a, block_samples(chain, 8, Plan(10 * 256, 256), 3))
    assert not np.array_equal(a, block_samples(chain, 7, Plan(10 * 256, 256), 2))
    u = block_stream(7, 3).random((256, chain.n))
    assert np.array_equal(a, chain.lower + (chain.upper - chain.lower) * u)
    assert np.all((a >= chain.lower) & (a <= chain.upper))
    ref = np.random.default_rng(np.random.SeedSequence(7, spawn_key=(3,))).random((256, chain.n))
    assert np.array_equal(u, ref)


def test_sample_at_draws_any_sample_again():
    chain, _ = chain_of(rrc_pin.load("panda"))
    plan = Plan(3 * 512 - 11, 512)
    every = np.concatenate([block_samples(chain, 4, plan, b) for b in range(plan.blocks)])
    idx = [0, 511, 512, 700, 1024, plan.samples - 1]
    assert np.array_equal(sample_at(chain, 4, plan, idx), every[idx])
    assert np.array_equal(sample_at(chain, 4, plan, 700), every[700])
