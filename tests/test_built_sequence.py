"""SequenceChain against the plain list of the same items (the oracle: Python's own list)."""

from __future__ import annotations

from hypothesis import given
from hypothesis import strategies as st

from collisionlab.built_sequence import SequenceChain

parts = st.lists(st.lists(st.integers(), max_size=5), max_size=6)


@given(parts, st.integers(-40, 40), st.integers(-40, 40), st.integers(-40, 40))
def test_a_chain_reads_as_the_list_of_its_parts(pieces: list[list[int]], i: int, lo: int, hi: int) -> None:
    chain: SequenceChain[int] = SequenceChain()
    flat: list[int] = []
    for piece in pieces:
        chain.extend(piece)
        flat.extend(piece)
    assert len(chain) == len(flat)
    assert list(chain) == flat and chain == flat
    assert chain[lo:hi] == flat[lo:hi]
    if -len(flat) <= i < len(flat):
        assert chain[i] == flat[i]
    else:
        try:
            chain[i]
        except IndexError:
            pass
        else:
            raise AssertionError(f"index {i} of {len(flat)} items did not raise IndexError")


def test_a_chain_differs_from_a_sequence_of_other_items_or_length() -> None:
    chain = SequenceChain([1, 2, 3])
    assert chain != [1, 2] and chain != [1, 2, 4] and chain != "123" and chain != 3
    chain.append(4)
    assert chain == (1, 2, 3, 4)
