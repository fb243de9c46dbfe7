! refused: run line 5: FUNC f ended without RETURN
MODULE Broken
  VAR num r;
  PROC main()
    r := f(1);
  ENDPROC

  FUNC num f(num x)
    IF x > 1 RETURN x;
  ENDFUNC
ENDMODULE
