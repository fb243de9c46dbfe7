! refused: load line 4: unknown instruction MoveAbsJoint
MODULE Broken
  PROC main()
    MoveAbsJoint 1;
  ENDPROC
ENDMODULE
