! refused: run line 10: ERR_DIVZERO: division by zero
MODULE Broken
  VAR num d := 0;
  VAR num r;
  PROC main()
    r := half(4);
  ENDPROC

  FUNC num half(num x)
    RETURN x / d;
  ERROR
    IF ERRNO = ERR_DEV_MAXTIME RETURN 0;
    RAISE;
  ENDFUNC
ENDMODULE
