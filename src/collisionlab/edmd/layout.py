"""Where each number of an event-driven run lives: the columns of its arrays.

The state is an array of structures, the layout of the C reference (one ``struct`` per body):
row ``i`` of ``F`` (float64) and of ``IX`` (int32) hold everything body ``i``'s events touch, so
handling an event reads a few cache lines instead of one line from each of twenty arrays.
The constants are module globals; numba freezes them into the compiled code.

=========  ==============================================================================
``F``      position (``X..X+2``), velocity (``V..V+2``), time ``T`` at which position and
           velocity hold, collision counter ``COUNT``, neighbour-list centre (``C..C+2``),
           time ``TLAST`` of the last collision (the TC model), scheduled event time ``EVT``,
           the partner's counter when the event was scheduled ``PCOUNT``, the body's
           ``RADIUS`` and ``MASS`` (a mixture: each body its own)
``IX``      ``PARTNER`` (body, or wall ``0 .. 2 dim - 1``), event ``KIND``, the
           ``CELL`` its list centre lies in, calendar links ``HPOS, QID, QNEXT, QPREV``,
           neighbour count ``NNB``, ``EDGE`` (cell on a periodic face)
``NB``     neighbour lists, one row per body, ``NB[i, :IX[i, NNB]]``
``CI``     cells, one row per cell: how many bodies, then each one's float32 centre and index
           (``CF`` reads the same memory as float32; see :mod:`.cells`)
``P``      float parameters (``P_*``); ``Q`` int parameters (``Q_*``)
``G``      float accumulators (``G_*``); ``K`` int64 counters (``K_*``)
``buf``    events as they happen, ``EVENT_BRIEF`` or ``EVENT_FULL`` columns
``S``      each body's species (int32; empty when there is one); ``KS[a, b]`` (int64) the
           collisions of a body of ``a`` with one of ``b``, counted once for each body of ``a``
           in it (a pair of one species counts twice); ``SE[a]`` species ``a``'s kinetic
           energy, the time since which it holds, and its integral over time up to then
=========  ==============================================================================

Walls are numbered ``2 k`` (the low side of axis ``k``) and ``2 k + 1`` (the high side).
"""

from __future__ import annotations

__all__ = [
    "CELL",
    "COUNT",
    "EDGE",
    "EVENT_BRIEF",
    "EVENT_FULL",
    "EVT",
    "G_KINETIC",
    "G_LOST",
    "G_MAX_OVERLAP",
    "G_NOW",
    "G_VIRIAL",
    "G_WALL",
    "HPOS",
    "KIND",
    "KIND_NLIST",
    "KIND_NONE",
    "KIND_PAIR",
    "KIND_WALL",
    "K_AHEAD",
    "K_BUCKETED",
    "K_BUFFERED",
    "K_CUR",
    "K_EVENTS",
    "K_HEAP",
    "K_NLIST",
    "K_PAIRS",
    "K_STALE",
    "K_WALLS",
    "MASS",
    "NB_UNSCHEDULED",
    "NF",
    "NG",
    "NI",
    "NK",
    "NNB",
    "NP",
    "NQ",
    "PARTNER",
    "PCOUNT",
    "P_BLOCK",
    "P_CUT",
    "P_E",
    "P_G",
    "P_INV_H",
    "P_L",
    "P_MIXED",
    "P_RADII",
    "P_RADIUS",
    "P_REACH",
    "P_SKIN",
    "P_TC",
    "QID",
    "QNEXT",
    "QPREV",
    "Q_DIM",
    "Q_NB",
    "Q_NC",
    "Q_PERIODIC",
    "RADIUS",
    "TLAST",
    "C",
    "T",
    "V",
    "X",
]

# F: float64 per body. Position, velocity, their time and the collision counter come first:
# they are what predicting a neighbour's collision reads (the counter of the neighbour that
# becomes the partner), 64 contiguous bytes. A row is 128 bytes (2 columns unused), so that in
# arrays that start on a cache line (arrays.aligned_zeros) those 64 bytes are one line in every
# row: 96-byte rows put every other row's across two, and with a million bodies every
# neighbour's row is a cache miss (1M, T = 4: 257 k collisions/s against 214 k/s with 96-byte
# rows); the counters were in IX, one more miss for the partner's (1M: 216 k/s against 198 k/s).
# A mixture's radius and mass fill the second line; a prediction reads a neighbour's radius from
# ``P[P_RADII + j]`` (8 bytes a body, at hand), only when the radii differ (``P_MIXED``): from
# the row's second line it cost every neighbour one more cache line (3D binary, N 4,000: 1.31x
# the time per collision of one kind, against 1.18x, bench/LOG.md).
X = 0
V = 3
T = 6
COUNT = 7  # collisions so far (a float64 counts exactly to 2^53)
C = 8
TLAST = 11
EVT = 12
PCOUNT = 13  # the partner's COUNT when the event was scheduled
RADIUS = 14
MASS = 15
NF = 16

# IX: int32 per body
PARTNER = 0
KIND = 1
CELL = 2
HPOS = 3  # >= 0: index in the heap; -1: in a list (QID); NB_UNSCHEDULED: no event
QID = 4
QNEXT = 5
QPREV = 6
NNB = 7
EDGE = 8  # 1 if the body's cell touches a periodic face (only then are nearest images needed)
NI = 9

#: ``IX[i, HPOS]`` of a body with no event (it does not move and nothing is coming).
NB_UNSCHEDULED = -2

# event kinds
KIND_NONE = 0
KIND_PAIR = 1
KIND_WALL = 2
KIND_NLIST = 3

# P: float parameters
P_L = 0  # box sides, 3 values
P_RADIUS = 3  # the largest radius (each body's own is F[i, RADIUS])
P_MIXED = 4  # 1.0 when the radii differ: a pair's contact distance is then r_i + r_j, read per pair
P_E = 5  # restitution
P_TC = 6  # TC model: a collision within this time of a body's previous one is elastic
P_G = 7  # gravity, along -y
P_CUT = 8  # neighbour-list reach between list centres (shell times the diameter)
P_SKIN = 9  # how far a body may drift from its list centre
P_BLOCK = 10  # calendar: time span of one block
P_INV_H = 11  # inverse cell sides, 3 values
P_REACH = 14  # P_CUT and a margin for the float32 centres of the cells (see cells.py)
NP = 15
#: A mixture's P goes on with each body's radius, in storage order: ``P[P_RADII + j]``, what a
#: prediction reads for each neighbour (a small array at hand, where ``F[j, RADIUS]`` is on the
#: second cache line of the neighbour's row).
P_RADII = NP

# Q: int parameters
Q_DIM = 0
Q_PERIODIC = 1
Q_NC = 2  # cells per axis, 3 values
Q_NB = 5  # calendar: number of ring lists (the overflow list is one more)
NQ = 6

# G: float64 accumulators
G_NOW = 0
G_VIRIAL = 1  # sum over pair collisions of r_ij . delta p_i (the collision virial)
G_MAX_OVERLAP = 2  # deepest overlap met at a contact, in length units
G_LOST = 3  # kinetic energy taken by inelastic collisions
G_WALL = 4  # momentum given to each wall, 6 values
G_KINETIC = 10  # kinetic energy the collisions changed, measured from the velocities before and after
NG = 11

# K: int64 counters and calendar state
K_PAIRS = 0
K_WALLS = 1
K_EVENTS = 2
K_NLIST = 3
K_STALE = 4
K_HEAP = 5  # bodies in the heap
K_CUR = 6  # index of the current block
K_BUCKETED = 7  # bodies in the ring lists (not the overflow)
K_BUFFERED = 8  # events written into the event buffer
K_AHEAD = 9  # calendar: the body of the next block's list whose rows are being fetched, or -1
NK = 10

# The event buffer's columns: time, body a, body b (a wall: ``-1 - wall``), impulse; a buffer
# with ``EVENT_FULL`` columns also gets the working: the unit normal from a to b (3), the
# contact point (3), the normal speed before ``(v_b - v_a) . n`` (negative: approaching), the
# restitution applied, then the velocities of a before, b before, a after, b after (3 each; a
# wall's are 0).
EVENT_BRIEF = 4
EVENT_FULL = 24
