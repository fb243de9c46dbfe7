! refused: load line 6: ReadBin has no optional argument \Tim
MODULE Broken
  VAR iodev ch;
  VAR num b;
  PROC main()
    b := ReadBin(ch \Tim:=0.1);
  ENDPROC
ENDMODULE
