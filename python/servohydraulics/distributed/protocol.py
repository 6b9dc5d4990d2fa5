"""The element/site wire protocol that OpenSees' ``genericClient`` element and
OpenFresco's clients speak, written from its description (docs/distributed.md).

A connection starts with the client's handshake: 11 native int32, the control sizes
(displacement, velocity, acceleration, force, time), the data-acquisition sizes of the
same five, then ``data_size``.  Every later message, both ways, is exactly ``data_size``
native float64 with no header.  A request's element 0 is an action code (:class:`Action`)
and its payload follows from element 1 in the order of :data:`QUANTITIES`, each as long
as its control size; a reply starts at element 0 (the acquired response packed by the
acquisition sizes, one quantity, or an n x n matrix in column-major order) and is padded
with zeros to ``data_size``.

This module only encodes, decodes and checks sizes; it holds no socket.
"""

from __future__ import annotations

import struct
from dataclasses import dataclass
from enum import IntEnum

import numpy as np

#: The quantities of a message's payload, in wire order.
QUANTITIES = ("displacement", "velocity", "acceleration", "force", "time")
#: The handshake: 11 native int32.
HANDSHAKE = struct.Struct("=11i")
#: Upper bound on data_size a server accepts (float64 per message: 512 KiB): a bound on what
#: one malformed handshake can make the server allocate.
MAX_DATA_SIZE = 65536


class Action(IntEnum):
    """Element 0 of a request."""

    SET_TRIAL_RESPONSE = 3   #: the trial response follows (no reply)
    COMMIT_STATE = 5         #: the trial step is final (no reply)
    GET_DAQ_RESPONSE = 6     #: reply: the acquired response, packed by the acquisition sizes
    GET_DISPLACEMENT = 7     #: reply: n displacements [m]
    GET_VELOCITY = 8         #: reply: n velocities [m/s]
    GET_ACCELERATION = 9     #: reply: n accelerations [m/s^2]
    GET_FORCE = 10           #: reply: n forces [N]
    GET_TIME = 11            #: reply: the site's time [s]
    GET_INITIAL_STIFFNESS = 12  #: reply: n x n [N/m], column-major
    GET_TANGENT_STIFFNESS = 13  #: reply: n x n [N/m], column-major
    GET_DAMPING = 14         #: reply: n x n [N s/m], column-major
    GET_MASS = 15            #: reply: n x n [kg], column-major
    STOP = 99                #: the client is done (no reply)


#: The actions the server answers with a message, and those it does not.
REPLIES = frozenset(a for a in Action if 6 <= a <= 15)
#: get displacement ... get time: the quantity each returns.
QUANTITY_OF = {Action.GET_DISPLACEMENT: "displacement", Action.GET_VELOCITY: "velocity",
               Action.GET_ACCELERATION: "acceleration", Action.GET_FORCE: "force", Action.GET_TIME: "time"}


class ProtocolError(ValueError):
    """A peer broke the protocol: the message says how (the connection's logged reason)."""


@dataclass(frozen=True)
class Sizes:
    """The handshake: control and acquisition sizes by quantity, and data_size."""

    control: tuple[int, int, int, int, int]
    daq: tuple[int, int, int, int, int]
    data_size: int

    @classmethod
    def from_bytes(cls, raw: bytes) -> Sizes:
        if len(raw) != HANDSHAKE.size:
            raise ProtocolError(f"handshake of {len(raw)} bytes, expected {HANDSHAKE.size} (11 int32)")
        v = HANDSHAKE.unpack(raw)
        return cls(tuple(v[0:5]), tuple(v[5:10]), v[10])

    def to_bytes(self) -> bytes:
        return HANDSHAKE.pack(*self.control, *self.daq, self.data_size)

    @property
    def message_bytes(self) -> int:
        return 8 * self.data_size

    def offsets(self, sizes: tuple[int, ...], start: int) -> dict[str, slice]:
        out, i = {}, start
        for name, n in zip(QUANTITIES, sizes):
            out[name] = slice(i, i + n)
            i += n
        return out

    def check(self, n: int, *, force_control: bool = False, max_data_size: int = MAX_DATA_SIZE) -> None:
        """Raises ProtocolError unless these sizes fit a site of ``n`` actuators: displacement
        control of all n (force control only if ``force_control``), velocity and acceleration
        0 or n, time 0 or 1, acquisition sizes 0 or n (time 0 or 1), and a data_size that
        holds the largest message (1 + the control sizes, the acquisition sizes, n x n) and is at
        most ``max_data_size``."""
        names = QUANTITIES
        for which, sizes in (("control", self.control), ("acquisition", self.daq)):
            for name, s in zip(names, sizes):
                allowed = (0, 1) if name == "time" else (0, n)
                if s not in allowed:
                    raise ProtocolError(f"{which} size of {name} = {s}: expected {' or '.join(map(str, allowed))} "
                                        f"(this site has {n} actuator{'s' * (n != 1)})")
        if self.control[0] != n:
            raise ProtocolError(f"control size of displacement = {self.control[0]}: expected {n} "
                                "(this site is displacement-controlled)")
        if self.control[3] and not force_control:
            raise ProtocolError(f"control size of force = {self.control[3]}: this site offers displacement control "
                                "only (expected 0)")
        need = max(1 + sum(self.control), sum(self.daq), n * n, 1)
        if not need <= self.data_size <= max_data_size:
            raise ProtocolError(f"data_size = {self.data_size}: expected {need} .. {max_data_size} "
                                f"(the largest message of these sizes holds {need} float64)")


def generic_client_sizes(n: int) -> Sizes:
    """The handshake OpenSees' ``element genericClient`` sends for n element DOFs, as recorded on
    the wire from OpenSeesPy 3.x (n = 1, 2, 3, 17): control (n, n, n, 0, 1), acquisition
    (0, 0, 0, n, 0), data_size max(256, n^2)."""
    return Sizes((n, n, n, 0, 1), (0, 0, 0, n, 0), max(256, 3 * n + 2, n * n))


_CODES = frozenset(int(a) for a in Action)
_ACTION_OF = {float(a): a for a in Action}


class Codec:
    """The server's side of one connection's sizes: requests decoded, replies packed into one
    preallocated buffer (the per-message work is a few NumPy views)."""

    def __init__(self, sizes: Sizes):
        self.sizes = sizes
        self._trial = [(name, slice(s.start - 1, s.stop - 1))
                       for name, s in sizes.offsets(sizes.control, 1).items() if s.stop > s.start]
        self._payload_end = 1 + sum(sizes.control)
        self._daq = [(name, n) for name, n in zip(QUANTITIES, sizes.daq) if n]
        self._out = np.zeros(sizes.data_size)

    def decode(self, message: bytes) -> tuple[Action, dict[str, np.ndarray]]:
        """A request: its action and, for a trial, the payload by quantity (copies).  ProtocolError
        for a message of the wrong length, an unknown action or a value that is not finite."""
        if len(message) != self.sizes.message_bytes:
            raise ProtocolError(f"message of {len(message)} bytes, expected data_size x 8 = "
                                f"{self.sizes.message_bytes}")
        v = np.frombuffer(message, dtype=np.float64)
        action = _ACTION_OF.get(float(v[0]))  # NaN is no key
        if action is None:
            raise ProtocolError(f"unknown action code {float(v[0])!r}: expected one of {sorted(_CODES)}")
        payload: dict[str, np.ndarray] = {}
        if action == Action.SET_TRIAL_RESPONSE:
            values = v[1:self._payload_end].copy()  # one copy, one check; the quantities are views of it
            if not np.isfinite(values).all():
                for name, s in self._trial:
                    bad = np.flatnonzero(~np.isfinite(values[s]))
                    if bad.size:
                        raise ProtocolError(f"trial {name}[{bad[0]}] = {values[s][bad[0]]}: not finite")
            for name, s in self._trial:
                payload[name] = values[s]
        return action, payload

    def reply(self, values: np.ndarray) -> bytes:
        """``values`` from element 0 (a matrix column-major), zeros after: data_size float64."""
        out = self._out
        out.fill(0.0)
        flat = np.asarray(values, dtype=float).reshape(-1, order="F")
        out[: flat.size] = flat
        return out.tobytes()

    def daq(self, response: dict[str, np.ndarray]) -> bytes:
        """The reply to GET_DAQ_RESPONSE: each acquired quantity by its acquisition size, in order."""
        out = self._out
        out.fill(0.0)
        i = 0
        for name, n in self._daq:
            out[i:i + n] = np.asarray(response[name], dtype=float).reshape(-1)[:n]
            i += n
        return out.tobytes()


def decode(message: bytes, sizes: Sizes) -> tuple[Action, dict[str, np.ndarray]]:
    """One request (Codec(sizes).decode)."""
    return Codec(sizes).decode(message)


def request(action: Action, sizes: Sizes, **values) -> bytes:
    """A request message: the action code and, for a trial, the payload (the client's side)."""
    v = np.zeros(sizes.data_size)
    v[0] = float(action)
    for name, s in sizes.offsets(sizes.control, 1).items():
        if name in values:
            v[s] = np.asarray(values[name], dtype=float).reshape(-1)[: s.stop - s.start]
    return v.tobytes()


def unpack_daq(message: bytes, sizes: Sizes) -> dict[str, np.ndarray]:
    """The client's side of Codec.daq: the acquired quantities by name."""
    v = np.frombuffer(message, dtype=np.float64)
    return {name: v[s].copy() for name, s in sizes.offsets(sizes.daq, 0).items() if s.stop > s.start}
