"""Typing stubs of the compiled module (python/src/lib.rs)."""

from typing import Any, Callable, List, Mapping, Optional, Tuple, Union

# What a frame may be given as: copied, never kept.
BytesLike = Union[bytes, bytearray, memoryview]

class HiperfaceError(Exception): ...

class MalformedRequest(HiperfaceError):
    """args: (message, fault code): 0x0A checksum, 0x0B unknown command, 0x0C too short
    or wrong length (000:2.3.3, 000:T48-T49)."""

class ProfileError(HiperfaceError):
    """A profile that cannot be loaded: the file, line and field."""

def catalogue(side: str) -> str: ...
def checksum(data: BytesLike) -> int: ...
def seal(frame: BytesLike) -> bytes: ...
def is_valid(frame: BytesLike) -> bool: ...
def decode_request(frame: BytesLike) -> Request: ...
def verify_vectors(path: str) -> Tuple[int, List[str]]: ...
def load_vectors(path: str) -> List[Vector]: ...

class Vector:
    id: str
    source: str
    clauses: List[str]
    profile: str
    command: str
    meaning: str
    result: str
    steps: int
    def verify(self) -> List[str]: ...
def decode_capture(
    path: str,
    on_exchange: Callable[[str], None],
    *,
    profile: str = "SRS50",
    baud: int = 9600,
    format: Optional[str] = None,
    samplerate: Optional[int] = None,
    tolerance_ms: Optional[float] = None,
    master_channel: Optional[str] = None,
    polling_period_ms: Optional[int] = None,
) -> str: ...

class Heard:
    """A request as the encoder under test received it (µs on the run's clock)."""

    bytes: bytes
    char_count: int
    #: "parity", "framing", "noise", "overrun" or None (000:T47).
    uart_fault: Optional[str]
    #: The ends (stop bits) of its first and last characters.
    first_us: int
    last_us: int
    #: The timeout after its last character: when it was known whole, now.
    complete_us: int

def certify_encoder(
    encoder: Any,
    profile: str = "SRS50",
    *,
    cases: Optional[str] = None,
    skip_writes: bool = False,
    skip_counter_change: bool = False,
    world: Optional[Mapping[str, Any]] = None,
) -> Tuple[str, str, str, str]: ...

def certify_master_in_process(
    master: Any,
    profile: str = "SRS50",
    *,
    scenarios: Optional[str] = None,
    polling_period_ms: int = 1000,
    name: Optional[str] = None,
    not_used: Optional[List[Union[int, str]]] = None,
) -> Tuple[str, str, str, str]: ...

class Request:
    address: int
    command: int
    data: bytes

class Transmission:
    frame: bytes
    earliest_start_us: int
    latest_start_us: int

class Slave:
    def __init__(self, profile: str) -> None: ...
    def receive(self, byte: int, at_us: int, fault: Optional[str] = None) -> None: ...
    def poll(self, now_us: int) -> Optional[Transmission]: ...
    def handle_frame(self, frame: BytesLike, at_us: int) -> Optional[bytes]: ...
    @property
    def inputs(self) -> Tuple[int, int, int, int]: ...
    def set_inputs(
        self,
        *,
        position: Optional[int] = None,
        speed: Optional[int] = None,
        temperature_c: Optional[int] = None,
        led_current_ma: Optional[int] = None,
    ) -> None: ...

class Grade:
    verdict: str
    clause: str
    reason: str

class Oracle:
    def __init__(self, exact: bool = False) -> None: ...
    def grade(
        self, slave: Slave, request: BytesLike, at_us: int, reply: Optional[BytesLike], uart_fault: bool = False
    ) -> Grade: ...

#: Every case verdict's name, the worst first, as the core spells it.
CASE_VERDICTS: Tuple[str, ...]
#: Every UART fault's name (000:T47), as Heard.uart_fault and Slave.receive spell it.
UART_FAULTS: Tuple[str, ...]
