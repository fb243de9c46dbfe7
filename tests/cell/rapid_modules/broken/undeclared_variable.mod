! refused: load line 6: y is not declared
MODULE Broken
  VAR num x;
  PROC main()
    x := 1;
    x := y + 1;
  ENDPROC
ENDMODULE
