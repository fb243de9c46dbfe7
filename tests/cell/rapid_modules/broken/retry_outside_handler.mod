! refused: load line 4: RETRY outside an ERROR handler
MODULE Broken
  PROC main()
    RETRY;
  ENDPROC
ENDMODULE
