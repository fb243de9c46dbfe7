"""Predefined data of RAPID the module uses: error numbers (``errnum``), integer types of
``PackRawBytes \\IntX`` (``inttypes``) and the manual's number ranges.

The ``ERR_*`` values are this interpreter's own numbering (modules use the names only);
the ``inttypes`` values are RAPID's (USINT 1, UINT 2, UDINT 4, SINT -1, INT -2, DINT -4,
LINT -8, ULINT 8)."""

from __future__ import annotations

#: a num holds integers exactly in this range (RAPID manual, data type num)
NUM_INT_MAX = 8388608
#: a dnum holds integers exactly in this range (RAPID manual, data type dnum)
DNUM_INT_MAX = 4503599627370496
#: longest string (characters) and largest rawbytes (bytes)
STRING_MAX = 80
RAWBYTES_MAX = 1024

_ERR_NAMES = [
    "ERR_ARGVALERR",
    "ERR_OUTOFBND",
    "ERR_DIVZERO",
    "ERR_STRTOOLONG",
    "ERR_NUMOVERFLOW",
    "ERR_DEV_MAXTIME",
    "ERR_FILEOPEN",
    "ERR_FILEACC",
    "ERR_FILEEOF",
    "ERR_RANYBIN_LEN",
    "ERR_SOCK_TIMEOUT",
    "ERR_SOCK_CLOSED",
    "ERR_SOCK_ADDR_INUSE",
    "ERR_SOCK_NET_UNREACH",
    "ERR_ALIASIO_DEF",
    "ERR_NORUNUNIT",
    "ERR_INT_NOTVAL",
    "ERR_INT_MAXVAL",
    "ERR_ARGNOTPER",
    "ERR_UNLOAD",
    "ERR_EXCRTYMAX",
    "ERR_RETRY_CONFLICT",
]
#: the predefined error numbers (errnum constants)
ERRNOS: dict[str, int] = {name: 1001 + i for i, name in enumerate(_ERR_NAMES)}

#: inttypes: bytes and signedness of each \IntX constant (value -> (size, signed))
INTTYPES: dict[str, int] = {
    "USINT": 1, "UINT": 2, "UDINT": 4, "ULINT": 8,
    "SINT": -1, "INT": -2, "DINT": -4, "LINT": -8,
}  # fmt: skip

#: socketstatus constants of SocketGetStatus
SOCKET_STATES: dict[str, int] = {
    "SOCKET_CREATED": 1, "SOCKET_CONNECTED": 2, "SOCKET_BOUND": 3, "SOCKET_LISTENING": 4,
    "SOCKET_CLOSED": 5,
}  # fmt: skip
