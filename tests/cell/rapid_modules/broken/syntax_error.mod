! refused: load line 7: syntax error at 'ENDPROC'
MODULE Broken
  VAR num x;
  PROC main()
    IF x = 1 THEN
      x := 2;
  ENDPROC
ENDMODULE
