! refused: load line 5: UnpackRawBytes takes 3 arguments (RawData, StartIndex, Value), 2 given
MODULE Broken
  VAR rawbytes raw;
  PROC main()
    UnpackRawBytes raw, 1 \IntX:=USINT;
  ENDPROC
ENDMODULE
