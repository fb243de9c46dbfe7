! refused: run line 7: ERR_ARGVALERR: 9000000 is not an integer in -8388607..8388608 (num)
MODULE Broken
  VAR rawbytes raw;
  VAR num big := 9000000;
  PROC main()
    PackRawBytes 8388608, raw, 1 \IntX:=DINT;
    PackRawBytes big, raw, 1 \IntX:=DINT;
  ENDPROC
ENDMODULE
