! refused: load line 5: type mismatch: string where num is expected
MODULE Broken
  VAR num n;
  PROC main()
    n := "seven";
  ENDPROC
ENDMODULE
