"""The interpreter's RAPID semantics: num in single precision and dnum in double, FOR counting
down without STEP, value copies of records and arrays, VAR arguments by reference, ERROR
handlers with RETRY, TRYNEXT, RETURN and RAISE, and the \\IntX ranges of a num."""

from __future__ import annotations

import numpy as np
import pytest

from cell.rapid.interp import Program, RapidStopped

MODULE = """
MODULE Semantics
  VAR num tries := 0;
  VAR rawbytes raw;

  FUNC num numSum(num a, num b)
    RETURN a + b;
  ENDFUNC

  FUNC dnum dnumSum(dnum a, dnum b)
    RETURN a + b;
  ENDFUNC

  FUNC num countDown(num a, num b)
    VAR num n := 0;
    FOR i FROM a TO b DO
      n := n + 1;
    ENDFOR
    RETURN n;
  ENDFUNC

  FUNC num copies()
    VAR jointtarget a;
    VAR jointtarget b;
    a.robax.rax_1 := 1;
    b := a;
    b.robax.rax_1 := 2;
    RETURN a.robax.rax_1 * 10 + b.robax.rax_1;
  ENDFUNC

  PROC bump(VAR num x)
    x := x + 1;
  ENDPROC

  FUNC num byRef()
    VAR num k := 5;
    bump k;
    bump k;
    RETURN k;
  ENDFUNC

  FUNC num retried()
    VAR num a{2};
    tries := 0;
    tries := tries + 1;
    a{tries + 1} := 7;
    RETURN tries;
  ERROR
    IF ERRNO = ERR_OUTOFBND THEN
      tries := 0;
      RETRY;
    ENDIF
  ENDFUNC

  FUNC num skipped()
    VAR num a{2};
    VAR num r := 1;
    a{3} := 1;
    r := 2;
    RETURN r;
  ERROR
    TRYNEXT;
  ENDFUNC

  FUNC num raised()
    RETURN inner();
  ERROR
    IF ERRNO = ERR_DIVZERO RETURN -1;
    RAISE;
  ENDFUNC

  FUNC num inner()
    VAR num z := 0;
    RETURN 1 / z;
  ERROR
    RAISE;
  ENDFUNC

  PROC packBig(num v)
    PackRawBytes v, raw, 1 \\IntX:=UDINT;
  ENDPROC

  PROC packBigD(dnum v)
    PackRawBytes v, raw, 1 \\IntX:=UDINT;
  ENDPROC
ENDMODULE
"""


@pytest.fixture(scope="module")
def prog() -> Program:
    return Program(MODULE, "semantics.mod")


def test_num_is_single_and_dnum_double(prog: Program) -> None:
    assert prog.call("numSum", 16777216, 1) == 16777216  # 2**24 + 1 is no single
    assert prog.call("dnumSum", 16777216, 1) == 16777217
    v = prog.call("numSum", 0.1, 0.2)
    assert isinstance(v, np.float32) and v == np.float32(0.1) + np.float32(0.2)


def test_for_without_step_counts_down(prog: Program) -> None:
    assert prog.call("countDown", 1, 3) == 3
    assert prog.call("countDown", 1, 0) == 2  # 1, 0: not an empty loop
    assert prog.call("countDown", 3, 3) == 1


def test_records_copied_and_var_arguments_by_reference(prog: Program) -> None:
    assert prog.call("copies") == 12
    assert prog.call("byRef") == 7


def test_error_handlers(prog: Program) -> None:
    assert prog.call("retried") == 1  # a{2} out of range once, RETRY from tries := 0
    assert prog.call("skipped") == 2  # TRYNEXT past the bad index
    assert prog.call("raised") == -1  # RAISE from inner to the caller's handler


def test_num_keeps_integers_exact_to_8388608_only(prog: Program) -> None:
    prog.call("packBig", 8388608)
    with pytest.raises(RapidStopped, match=r"ERR_ARGVALERR.*8388610"):
        prog.call("packBig", 8388610)
    prog.call("packBigD", 4294967295)
    assert prog.global_value("raw").valid() == b"\xff\xff\xff\xff"
