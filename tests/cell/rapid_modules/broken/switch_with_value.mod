! refused: load line 5: \Bin of Open is a switch and takes no value
MODULE Broken
  VAR iodev ch;
  PROC main()
    Open "com1:", ch \Bin:=1;
  ENDPROC
ENDMODULE
