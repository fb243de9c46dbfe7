! refused: load line 5: \Float4 and \IntX of PackRawBytes exclude each other
MODULE Broken
  VAR rawbytes raw;
  PROC main()
    PackRawBytes 1, raw, 1 \IntX:=USINT \Float4;
  ENDPROC
ENDMODULE
