! refused: load line 5: CONST HC_RAW is read-only
MODULE Broken
  CONST num HC_RAW := 3;
  PROC main()
    ClkReset HC_RAW;
  ENDPROC
ENDMODULE
