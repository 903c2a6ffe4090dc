"""Pair sums (refsph.neighbours): PairSum and PairBlocks against plain bincount sums; the block layout and the
thread count do not change a single bit of the result; bad input is refused."""
import numpy as np
import pytest

from refsph.neighbours import PairBlocks, PairSum, find_pairs


def pairs_and_values(n=400, seed=3):
    rng = np.random.default_rng(seed)
    x = rng.uniform(0.0, 1.0, (n, 2))
    I, J = find_pairs(x, 0.09)
    return I, J, rng.normal(size=len(I)), rng.normal(size=n)


def plain_sums(I, J, t, w, n, sign):
    """sum_j w_j t_ij into i, sign * w_i t_ij into j, one pair at a time."""
    out = np.zeros(n)
    for i, j, tp in zip(I, J, t):
        out[i] += w[j] * tp
        out[j] += sign * w[i] * tp
    return out


@pytest.mark.parametrize("sign", [1.0, -1.0])
def test_pair_sum_matches_plain_loop(sign):
    I, J, t, w = pairs_and_values()
    ps = PairSum(I, J, 400)
    got = ps.symmetric(t, w) if sign > 0 else ps.antisymmetric(t, w)
    assert np.allclose(got, plain_sums(I, J, t, w, 400, sign), rtol=1e-12, atol=1e-12)


@pytest.mark.parametrize("size", [1, 37, 500, 10**6])
def test_pair_blocks_add_up_to_the_whole_sum(size):
    I, J, t, w = pairs_and_values()
    blocks = PairBlocks(I, J, 400, size=size)
    assert sum(len(b.I) for b in blocks.blocks) == len(I)
    for b in blocks.blocks:                               # a window holds every particle its pairs touch
        assert b.window.start <= min(b.I.min(), b.J.min()) and max(b.I.max(), b.J.max()) < b.window.stop

    def block_sum(b):
        return b.sums.antisymmetric(t[b.sl], b.local(w))

    got = blocks.reduce(block_sum)
    assert got.shape == (400,)
    assert np.allclose(got, plain_sums(I, J, t, w, 400, -1.0), rtol=1e-12, atol=1e-12)


def test_threads_give_the_same_bits():
    I, J, t, w = pairs_and_values(n=2000)

    def block_sums(b):                                    # several rows per block, as the rate functions return
        return np.stack([b.sums.symmetric(t[b.sl], b.local(w)), b.sums.antisymmetric(t[b.sl] ** 2, b.local(w))])

    one = PairBlocks(I, J, 2000, size=1000, threads=1).reduce(block_sums)
    many = PairBlocks(I, J, 2000, size=1000, threads=3)
    assert len(many.blocks) > 3
    assert np.array_equal(one, many.reduce(block_sums))
    assert many.map(lambda k: k * k, range(5)) == [0, 1, 4, 9, 16]       # any independent tasks, in order
    many.close()


def test_empty_pair_list():
    blocks = PairBlocks(np.zeros(0, dtype=int), np.zeros(0, dtype=int), 5)
    got = blocks.reduce(lambda b: b.sums.symmetric(np.zeros(0), b.local(np.ones(5))))
    assert np.array_equal(got, np.zeros(5))


def test_bad_input_is_refused():
    I, J, _, _ = pairs_and_values()
    with pytest.raises(ValueError, match="block size"):
        PairBlocks(I, J, 400, size=0)
    with pytest.raises(ValueError, match="threads"):
        PairBlocks(I, J, 400, threads=0)
    with pytest.raises(ValueError, match=r"\[0, 10\)"):
        PairBlocks(I, J, 10)
    with pytest.raises(ValueError, match="one value per pair"):
        PairSum(I, J, 400).symmetric(np.ones(3), np.ones(400))
