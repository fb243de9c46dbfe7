! refused: run line 6: ERR_OUTOFBND: index 4 outside 1..3
MODULE Broken
  VAR num a{3};
  PROC main()
    FOR i FROM 1 TO 4 DO
      a{i} := i;
    ENDFOR
  ENDPROC
ENDMODULE
