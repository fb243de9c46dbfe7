MODULE OldFloat32Id
  ! The trajectory id as HolecellLink.mod computed it before issue 20: each row
  ! stored as DnumToNum(v) / 1000000 in a num array, the micro-degrees rebuilt
  ! with Round(row * 1000000). The test sets "wire" (rows as int32 LE) and
  ! "nRows", runs main and reads "result".
  CONST dnum CRC32_POLY := 3988292384;
  CONST dnum CRC32_INIT := 4294967295;
  VAR dnum crcTable{256};
  VAR num rows{50, 6};
  VAR num nRows := 0;
  VAR rawbytes wire;
  VAR dnum result := 0;

  PROC main()
    VAR dnum v;
    VAR dnum c;
    FOR n FROM 0 TO 255 DO
      c := NumToDnum(n);
      FOR k FROM 1 TO 8 DO
        IF BitAndDnum(c, 1) = 1 THEN
          c := BitXOrDnum(CRC32_POLY, BitRShDnum(c, 1));
        ELSE
          c := BitRShDnum(c, 1);
        ENDIF
      ENDFOR
      crcTable{n + 1} := c;
    ENDFOR
    FOR r FROM 1 TO nRows DO
      FOR a FROM 1 TO 6 DO
        UnpackRawBytes wire, 1 + 24 * (r - 1) + 4 * (a - 1), v \IntX:=DINT;
        rows{r, a} := DnumToNum(v) / 1000000;
      ENDFOR
    ENDFOR
    result := oldId();
  ENDPROC

  FUNC dnum crcRaw(dnum crc, VAR rawbytes raw, num first, num count)
    VAR num b;
    VAR dnum c;
    VAR num idx;
    c := crc;
    FOR i FROM first TO first + count - 1 DO
      UnpackRawBytes raw, i, b \IntX:=USINT;
      idx := DnumToNum(BitAndDnum(BitXOrDnum(c, NumToDnum(b)), 255));
      c := BitXOrDnum(crcTable{idx + 1}, BitRShDnum(c, 8));
    ENDFOR
    RETURN c;
  ENDFUNC

  ! the old hcTrajectoryId (a tour without stops)
  FUNC dnum oldId()
    VAR rawbytes b;
    VAR dnum c;
    c := CRC32_INIT;
    FOR r FROM 1 TO nRows DO
      FOR a FROM 1 TO 6 DO
        PackRawBytes NumToDnum(Round(rows{r, a} * 1000000)), b, 1 \IntX:=DINT;
        c := crcRaw(c, b, 1, 4);
      ENDFOR
    ENDFOR
    c := BitXOrDnum(c, CRC32_INIT);
    IF c = 0 c := 1;
    RETURN c;
  ENDFUNC
ENDMODULE
