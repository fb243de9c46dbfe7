! refused: run line 6: ERR_STRTOOLONG: string of 81 characters (max 80)
MODULE Broken
  VAR string s := "0123456789012345678901234567890123456789";
  PROC main()
    s := s + s;
    s := s + "x";
  ENDPROC
ENDMODULE
