MODULE HolecellLink
  !*****************************************************************************
  ! holecell controller link, controller side (protocol version 1).
  ! See docs/protocol.md. The constants below are shared with the Python side
  ! (cell.link.frame, cell.link.messages); tests/cell/test_cell_rapid.py checks
  ! that they are equal and that the CRC-32 routine reproduces zlib.crc32.
  !
  ! Runs in the motion task: PROC hcMain. Needs RobotWare 6 (dnum bit functions)
  ! or RobotWare 7, and six analog inputs aiTempJ1 .. aiTempJ6 (link
  ! temperatures, degC). The link (HC_TRANSPORT below):
  !   "serial": the serial channel configured as "com1:" (115200 8N1, no flow
  !             control); IRC5 only (OmniCore has no serial channel for RAPID);
  !   "socket": RAPID socket messaging, this controller a TCP server on
  !             HC_SOCKET_ADDRESS:HC_SOCKET_PORT; IRC5 needs RobotWare option
  !             616-1 PC Interface or 672-1 Socket Messaging; RobotWare 7 has it.
  ! Units on the wire: joints int32 micro-degrees, temperatures int32 milli-degC.
  !*****************************************************************************

  ! --- framing (cell.link.frame) -----------------------------------------------
  CONST num HC_SYNC1 := 165;
  CONST num HC_SYNC2 := 90;
  CONST num HC_MAX_PAYLOAD := 512;
  CONST dnum HC_CRC32_POLY := 3988292384;
  CONST dnum HC_CRC32_INIT := 4294967295;
  CONST dnum HC_CRC32_CHECK := 3421780262;
  CONST num HC_SEQ_UNKNOWN := 255;

  ! --- messages (cell.link.messages) -------------------------------------------
  CONST num HC_PROTOCOL_VERSION := 1;
  CONST num HC_ROWS_PER_CHUNK := 20;
  CONST num HC_STOPS_PER_CHUNK := 100;
  CONST num MSG_IDENTIFY := 1;
  CONST num MSG_HEARTBEAT := 2;
  CONST num MSG_STATUS := 3;
  CONST num MSG_LOAD_BEGIN := 16;
  CONST num MSG_LOAD_ROWS := 17;
  CONST num MSG_LOAD_STOPS := 18;
  CONST num MSG_LOAD_END := 19;
  CONST num MSG_EXECUTE := 32;
  CONST num MSG_MOVE_TO_STOP := 33;
  CONST num MSG_STOP := 34;
  CONST num MSG_ABORT := 35;
  CONST num MSG_RESET := 36;
  CONST num MSG_ACK := 128;
  CONST num MSG_NAK := 129;
  CONST num NAK_CRC := 1;
  CONST num NAK_UNKNOWN_TYPE := 2;
  CONST num NAK_BAD_PAYLOAD := 3;
  CONST num NAK_REFUSED := 4;
  CONST num NAK_NOT_LOADED := 5;
  CONST num ST_IDLE := 0;
  CONST num ST_MOVING := 1;
  CONST num ST_IN_POSITION := 2;
  CONST num ST_STOPPED := 3;
  CONST num ST_ESTOP := 4;
  CONST num ST_FAULT := 5;
  CONST num FLT_NONE := 0;
  CONST num FLT_ESTOP := 1;
  CONST num FLT_LINK_LOST := 2;
  CONST num FLT_OFF_PATH := 3;
  CONST num FLT_LOAD_ERROR := 4;

  ! --- this controller ---------------------------------------------------------
  CONST string HC_PORT := "com1:";
  CONST string HC_MODEL := "abb_irb2600_20_165";
  CONST string HC_NAME := "irc5-holecell";
  CONST num HC_MAX_ROWS := 10000;
  CONST num HC_MAX_STOPS := 500;
  CONST num HC_ROW_STEP := 10;
  CONST num HC_LINK_TIMEOUT_S := 1;
  CONST num HC_ON_PATH_TOL_DEG := 0.001;
  CONST num HC_IN_POS_TOL_DEG := 0.001;
  CONST num HC_N_TEMPS := 6;

  ! --- transport: "serial" (the channel HC_PORT) or "socket" (RAPID socket
  ! messaging, this controller the server on HC_SOCKET_ADDRESS:HC_SOCKET_PORT).
  ! Serial needs a configured serial channel; socket needs option 616-1 PC
  ! Interface or 672-1 Socket Messaging on IRC5 (RobotWare 6), and is part of
  ! RobotWare 7 (OmniCore). Only hcLinkOpen, hcLinkRead and hcLinkWrite differ.
  CONST string HC_TRANSPORT := "serial";
  CONST string HC_SOCKET_ADDRESS := "192.168.125.1";
  CONST num HC_SOCKET_PORT := 1025;
  CONST num HC_POLL_S := 0.002;
  ! longest wait for the rest of a frame on the serial channel (520 bytes take
  ! 45 ms at 115200 baud); a frame cut short is dropped and retransmitted
  CONST num HC_FRAME_S := 0.1;

  VAR iodev hcChan;
  VAR socketdev hcServer;
  VAR socketdev hcClient;
  VAR bool hcConnected := FALSE;
  VAR rawbytes hcRxChunk;
  VAR clock hcClock;
  VAR clock hcLinkClock;
  VAR dnum hcCrcTable{256};
  ! receive state machine
  VAR num hcRxState := 0;
  VAR num hcRxType;
  VAR num hcRxSeq;
  VAR num hcRxLen;
  VAR num hcRxCount;
  VAR dnum hcRxCrc;
  VAR rawbytes hcRxPay;
  VAR rawbytes hcRxHead;
  ! duplicate cache: last request (seq, crc) and its answer frame
  VAR num hcLastSeq := -1;
  VAR dnum hcLastCrc := 0;
  VAR rawbytes hcLastAnswer;
  VAR rawbytes hcAns;
  ! trajectory (degrees), stop rows (1-based), load progress and motion state.
  ! The trajectory id is the CRC-32 of the rows and stops as they arrive on the
  ! wire (int32/uint32): a num keeps integers exact only up to 8388608, so
  ! micro-degrees rebuilt from num degrees would differ past 8.4 deg.
  VAR num hcRows{HC_MAX_ROWS, 6};
  VAR num hcRowsIn := 0;
  VAR num hcStopsIn := 0;
  VAR dnum hcLoadCrc := 0;
  VAR num hcStops{HC_MAX_STOPS};
  VAR num hcNRows := 0;
  VAR num hcNStops := 0;
  VAR num hcDt := 0.004;
  VAR dnum hcTrajId := 0;
  VAR dnum hcLoadId := 0;
  VAR bool hcLoaded := FALSE;
  VAR num hcPos := 1;
  VAR num hcTargetRow := 0;
  VAR num hcTargetStop := -1;
  VAR num hcAtStop := -1;
  VAR num hcState := ST_IDLE;
  VAR num hcFault := FLT_NONE;
  PERS bool hcEstopLatched := FALSE;
  VAR signalai hcTemp{HC_N_TEMPS};

  PROC hcMain()
    hcInit;
    WHILE TRUE DO
      hcPollLine;
      hcWatchdog;
      hcMotionStep;
    ENDWHILE
  ENDPROC

  PROC hcInit()
    hcLinkOpen;
    hcCrcInit;
    ClkReset hcClock;
    ClkStart hcClock;
    ClkReset hcLinkClock;
    ClkStart hcLinkClock;
    FOR i FROM 1 TO HC_N_TEMPS DO
      AliasIO "aiTempJ" + NumToStr(i, 0), hcTemp{i};
    ENDFOR
    IF hcEstopLatched THEN
      hcState := ST_ESTOP;
      hcFault := FLT_ESTOP;
      hcAtStop := -1;
      hcTargetStop := -1;
    ENDIF
  ENDPROC

  ! --- CRC-32/ISO-HDLC (reflected, table driven) --------------------------------
  PROC hcCrcInit()
    VAR dnum c;
    FOR n FROM 0 TO 255 DO
      c := NumToDnum(n);
      FOR k FROM 1 TO 8 DO
        IF BitAndDnum(c, 1) = 1 THEN
          c := BitXOrDnum(HC_CRC32_POLY, BitRShDnum(c, 1));
        ELSE
          c := BitRShDnum(c, 1);
        ENDIF
      ENDFOR
      hcCrcTable{n + 1} := c;
    ENDFOR
  ENDPROC

  FUNC dnum hcCrcByte(dnum crc, num b)
    VAR num idx;
    idx := DnumToNum(BitAndDnum(BitXOrDnum(crc, NumToDnum(b)), 255));
    RETURN BitXOrDnum(hcCrcTable{idx + 1}, BitRShDnum(crc, 8));
  ENDFUNC

  FUNC dnum hcCrcRaw(dnum crc, VAR rawbytes raw, num first, num count)
    VAR num b;
    VAR dnum c;
    c := crc;
    ! a FOR without STEP counts down when FROM > TO: no loop for count 0
    IF count < 1 RETURN c;
    FOR i FROM first TO first + count - 1 DO
      UnpackRawBytes raw, i, b \IntX:=USINT;
      c := hcCrcByte(c, b);
    ENDFOR
    RETURN c;
  ENDFUNC

  ! --- transport ---------------------------------------------------------------
  PROC hcLinkOpen()
    IF HC_TRANSPORT = "socket" THEN
      SocketClose hcClient;
      SocketClose hcServer;
      hcConnected := FALSE;
      SocketCreate hcServer;
      SocketBind hcServer, HC_SOCKET_ADDRESS, HC_SOCKET_PORT;
      SocketListen hcServer;
    ELSE
      Close hcChan;
      Open HC_PORT, hcChan \Bin;
      ClearIOBuff hcChan;
    ENDIF
  ENDPROC

  ! Bytes received, in hcRxChunk; their number (0: none). Socket: what arrives
  ! within HC_POLL_S; serial: one byte within HC_POLL_S, or the "want" bytes of
  ! a frame's rest within HC_FRAME_S (else the frame is dropped).
  ! A socket client is accepted first; a closed one is dropped (the watchdog
  ! stops the arm) and the next one accepted.
  FUNC num hcLinkRead(num want)
    ClearRawBytes hcRxChunk;
    IF HC_TRANSPORT = "socket" THEN
      IF NOT hcConnected THEN
        SocketAccept hcServer, hcClient \Time:=HC_POLL_S;
        hcConnected := TRUE;
        hcRxState := 0;
      ENDIF
      SocketReceive hcClient \RawData:=hcRxChunk \Time:=HC_POLL_S;
    ELSEIF want = 1 THEN
      PackRawBytes ReadBin(hcChan \Time:=HC_POLL_S), hcRxChunk, 1 \IntX:=USINT;
    ELSE
      ReadRawBytes hcChan, hcRxChunk, want \Time:=HC_FRAME_S;
    ENDIF
    RETURN RawBytesLen(hcRxChunk);
  ERROR
    IF ERRNO = ERR_DEV_MAXTIME OR ERRNO = ERR_SOCK_TIMEOUT THEN
      IF want > 1 hcRxState := 0;
      RETURN 0;
    ELSEIF ERRNO = ERR_SOCK_CLOSED THEN
      SocketClose hcClient;
      hcConnected := FALSE;
      RETURN 0;
    ENDIF
    RAISE;
  ENDFUNC

  PROC hcLinkWrite(VAR rawbytes f)
    IF HC_TRANSPORT = "socket" THEN
      IF hcConnected SocketSend hcClient \RawData:=f;
    ELSE
      WriteRawBytes hcChan, f;
    ENDIF
  ERROR
    IF ERRNO = ERR_SOCK_CLOSED THEN
      SocketClose hcClient;
      hcConnected := FALSE;
      RETURN;
    ENDIF
    RAISE;
  ENDPROC

  ! --- receiving ---------------------------------------------------------------
  ! Byte-wise state machine. Unlike the Python decoder it does not rescan the
  ! bytes of a rejected frame; a frame swallowed that way is recovered by the
  ! host's retransmission.
  PROC hcPollLine()
    VAR num n;
    n := hcLinkRead(hcRxWant());
    WHILE n > 0 DO
      hcRxBytes n;
      n := hcLinkRead(hcRxWant());
    ENDWHILE
  ENDPROC

  ! bytes the receiver needs next: the rest of a header or of a payload and CRC
  FUNC num hcRxWant()
    IF hcRxState = 2 RETURN 4 - hcRxCount;
    IF hcRxState = 3 RETURN hcRxLen + 4 - hcRxCount;
    RETURN 1;
  ENDFUNC

  ! the n bytes of hcRxChunk: sync and header byte by byte, payload in one copy
  PROC hcRxBytes(num n)
    VAR num i := 1;
    VAR num b;
    VAR num k;
    WHILE i <= n DO
      IF hcRxState = 3 THEN
        k := Min(n - i + 1, hcRxLen + 4 - hcRxCount);
        CopyRawBytes hcRxChunk, i, hcRxPay, hcRxCount + 1 \NoOfBytes:=k;
        hcRxCount := hcRxCount + k;
        i := i + k;
        IF hcRxCount = hcRxLen + 4 THEN
          hcRxState := 0;
          hcFrameDone;
        ENDIF
      ELSE
        UnpackRawBytes hcRxChunk, i, b \IntX:=USINT;
        hcRxByte b;
        i := i + 1;
      ENDIF
    ENDWHILE
  ENDPROC

  ! sync and header (states 0 to 2); state 3 (payload) is hcRxBytes'
  PROC hcRxByte(num b)
    TEST hcRxState
    CASE 0:
      IF b = HC_SYNC1 hcRxState := 1;
    CASE 1:
      IF b = HC_SYNC2 THEN
        hcRxState := 2;
        hcRxCount := 0;
        ClearRawBytes hcRxHead;
      ELSEIF b <> HC_SYNC1 THEN
        hcRxState := 0;
      ENDIF
    CASE 2:
      hcRxCount := hcRxCount + 1;
      PackRawBytes b, hcRxHead, hcRxCount \IntX:=USINT;
      IF hcRxCount = 4 THEN
        UnpackRawBytes hcRxHead, 1, hcRxType \IntX:=USINT;
        UnpackRawBytes hcRxHead, 2, hcRxSeq \IntX:=USINT;
        UnpackRawBytes hcRxHead, 3, hcRxLen \IntX:=UINT;
        IF hcRxLen > HC_MAX_PAYLOAD THEN
          hcRxState := 0;
        ELSE
          hcRxCrc := hcCrcRaw(HC_CRC32_INIT, hcRxHead, 1, 4);
          ClearRawBytes hcRxPay;
          hcRxCount := 0;
          hcRxState := 3;
        ENDIF
      ENDIF
    ENDTEST
  ENDPROC

  PROC hcFrameDone()
    VAR dnum crc;
    VAR dnum got;
    crc := BitXOrDnum(hcCrcRaw(hcRxCrc, hcRxPay, 1, hcRxLen), HC_CRC32_INIT);
    UnpackRawBytes hcRxPay, hcRxLen + 1, got \IntX:=UDINT;
    IF crc <> got THEN
      hcSendNak HC_SEQ_UNKNOWN, NAK_CRC, "bad CRC";
      RETURN;
    ENDIF
    ClkReset hcLinkClock;
    IF hcRxType <> MSG_IDENTIFY AND hcRxSeq = hcLastSeq AND crc = hcLastCrc THEN
      hcLinkWrite hcLastAnswer;
      RETURN;
    ENDIF
    hcLastSeq := hcRxSeq;
    hcLastCrc := crc;
    hcDispatch;
  ENDPROC

  ! --- answering ---------------------------------------------------------------
  PROC hcSend(num msgType, num seq, VAR rawbytes pay)
    VAR rawbytes f;
    VAR num n;
    VAR dnum crc;
    n := RawBytesLen(pay);
    PackRawBytes HC_SYNC1, f, 1 \IntX:=USINT;
    PackRawBytes HC_SYNC2, f, 2 \IntX:=USINT;
    PackRawBytes msgType, f, 3 \IntX:=USINT;
    PackRawBytes seq, f, 4 \IntX:=USINT;
    PackRawBytes n, f, 5 \IntX:=UINT;
    IF n > 0 CopyRawBytes pay, 1, f, 7 \NoOfBytes:=n;
    crc := BitXOrDnum(hcCrcRaw(HC_CRC32_INIT, f, 3, n + 4), HC_CRC32_INIT);
    PackRawBytes crc, f, n + 7 \IntX:=UDINT;
    hcLinkWrite f;
    ClearRawBytes hcLastAnswer;
    CopyRawBytes f, 1, hcLastAnswer, 1;
  ENDPROC

  PROC hcAck()
    hcSend MSG_ACK, hcRxSeq, hcAns;
  ENDPROC

  PROC hcSendNak(num seq, num code, string text)
    ClearRawBytes hcAns;
    PackRawBytes code, hcAns, 1 \IntX:=USINT;
    PackRawBytes text, hcAns, 2 \ASCII;
    hcSend MSG_NAK, seq, hcAns;
  ENDPROC

  PROC hcDispatch()
    ClearRawBytes hcAns;
    TEST hcRxType
    CASE MSG_IDENTIFY:
      hcLastSeq := -1;
      PackRawBytes HC_PROTOCOL_VERSION, hcAns, 1 \IntX:=UINT;
      PackRawBytes 6, hcAns, 3 \IntX:=USINT;
      PackRawBytes StrLen(HC_MODEL), hcAns, 4 \IntX:=USINT;
      PackRawBytes HC_MODEL, hcAns, 5 \ASCII;
      PackRawBytes StrLen(HC_NAME), hcAns, 5 + StrLen(HC_MODEL) \IntX:=USINT;
      PackRawBytes HC_NAME, hcAns, 6 + StrLen(HC_MODEL) \ASCII;
      hcAck;
    CASE MSG_HEARTBEAT:
      hcAck;
    CASE MSG_STATUS:
      hcStatus;
    CASE MSG_LOAD_BEGIN:
      hcLoadBegin;
    CASE MSG_LOAD_ROWS:
      hcLoadRows;
    CASE MSG_LOAD_STOPS:
      hcLoadStops;
    CASE MSG_LOAD_END:
      hcLoadEnd;
    CASE MSG_EXECUTE:
      hcStartMove hcNRows, hcNStops;
    CASE MSG_MOVE_TO_STOP:
      hcMoveToStop;
    CASE MSG_STOP:
      ! a latched emergency stop or fault stays until RESET
      IF hcState = ST_MOVING hcHalt ST_STOPPED, FLT_NONE;
      hcAck;
    CASE MSG_ABORT:
      IF hcState = ST_MOVING hcHalt ST_STOPPED, FLT_NONE;
      hcLoaded := FALSE;
      hcTrajId := 0;
      hcAtStop := -1;
      IF hcState <> ST_ESTOP AND hcState <> ST_FAULT hcState := ST_IDLE;
      hcAck;
    CASE MSG_RESET:
      IF hcState = ST_ESTOP OR hcState = ST_FAULT THEN
        hcState := ST_IDLE;
        IF hcLoaded hcState := ST_STOPPED;
      ENDIF
      hcEstopLatched := FALSE;
      hcFault := FLT_NONE;
      hcAck;
    DEFAULT:
      hcSendNak hcRxSeq, NAK_UNKNOWN_TYPE, "unknown message type";
    ENDTEST
  ERROR
    ! a payload shorter than its message needs: read past its valid bytes
    IF ERRNO = ERR_OUTOFBND THEN
      hcSendNak hcRxSeq, NAK_BAD_PAYLOAD, "payload too short";
      RETURN;
    ENDIF
    RAISE;
  ENDPROC

  PROC hcStatus()
    VAR jointtarget j;
    j := CJointT();
    PackRawBytes hcState, hcAns, 1 \IntX:=USINT;
    PackRawBytes hcFault, hcAns, 2 \IntX:=USINT;
    PackRawBytes hcAtStop, hcAns, 3 \IntX:=INT;
    PackRawBytes hcTargetStop, hcAns, 5 \IntX:=INT;
    PackRawBytes hcPos - 1, hcAns, 7 \IntX:=UDINT;
    PackRawBytes hcTrajId, hcAns, 11 \IntX:=UDINT;
    PackRawBytes NumToDnum(Round(ClkRead(hcClock) * 1000)) * 1000, hcAns, 15 \IntX:=LINT;
    PackRawBytes Round(NumToDnum(j.robax.rax_1) * 1000000), hcAns, 23 \IntX:=DINT;
    PackRawBytes Round(NumToDnum(j.robax.rax_2) * 1000000), hcAns, 27 \IntX:=DINT;
    PackRawBytes Round(NumToDnum(j.robax.rax_3) * 1000000), hcAns, 31 \IntX:=DINT;
    PackRawBytes Round(NumToDnum(j.robax.rax_4) * 1000000), hcAns, 35 \IntX:=DINT;
    PackRawBytes Round(NumToDnum(j.robax.rax_5) * 1000000), hcAns, 39 \IntX:=DINT;
    PackRawBytes Round(NumToDnum(j.robax.rax_6) * 1000000), hcAns, 43 \IntX:=DINT;
    PackRawBytes HC_N_TEMPS, hcAns, 47 \IntX:=USINT;
    FOR i FROM 1 TO HC_N_TEMPS DO
      PackRawBytes Round(AInput(hcTemp{i}) * 1000), hcAns, 44 + 4 * i \IntX:=DINT;
    ENDFOR
    hcAck;
  ENDPROC

  ! --- loading -----------------------------------------------------------------
  PROC hcLoadBegin()
    VAR dnum id;
    VAR num rows;
    VAR num stops;
    VAR num dtUs;
    IF hcState = ST_MOVING THEN
      hcSendNak hcRxSeq, NAK_REFUSED, "cannot load while moving";
      RETURN;
    ENDIF
    UnpackRawBytes hcRxPay, 1, id \IntX:=UDINT;
    UnpackRawBytes hcRxPay, 5, rows \IntX:=UDINT;
    UnpackRawBytes hcRxPay, 9, stops \IntX:=UINT;
    UnpackRawBytes hcRxPay, 11, dtUs \IntX:=DINT;
    IF hcLoaded AND id = hcTrajId THEN
      PackRawBytes 1, hcAns, 1 \IntX:=USINT;
      hcAck;
      RETURN;
    ENDIF
    IF rows < 2 OR rows > HC_MAX_ROWS OR stops > HC_MAX_STOPS OR dtUs <= 0 THEN
      hcSendNak hcRxSeq, NAK_BAD_PAYLOAD, "trajectory too large or empty";
      RETURN;
    ENDIF
    hcLoaded := FALSE;
    hcLoadId := id;
    hcRowsIn := 0;
    hcStopsIn := 0;
    hcLoadCrc := HC_CRC32_INIT;
    hcNRows := rows;
    hcNStops := stops;
    hcDt := dtUs / 1000000;
    PackRawBytes 0, hcAns, 1 \IntX:=USINT;
    hcAck;
  ENDPROC

  PROC hcLoadRows()
    VAR num first;
    VAR num count;
    VAR dnum v;
    UnpackRawBytes hcRxPay, 1, first \IntX:=UDINT;
    UnpackRawBytes hcRxPay, 5, count \IntX:=USINT;
    IF count < 1 OR count > HC_ROWS_PER_CHUNK OR first + count > hcNRows THEN
      hcSendNak hcRxSeq, NAK_BAD_PAYLOAD, "rows out of range";
      RETURN;
    ENDIF
    IF first + count <= hcRowsIn THEN
      ! rows already held (a repeated chunk)
      hcAck;
      RETURN;
    ENDIF
    IF first <> hcRowsIn THEN
      hcSendNak hcRxSeq, NAK_BAD_PAYLOAD, "rows out of order";
      RETURN;
    ENDIF
    FOR r FROM 1 TO count DO
      FOR a FROM 1 TO 6 DO
        UnpackRawBytes hcRxPay, 6 + 24 * (r - 1) + 4 * (a - 1), v \IntX:=DINT;
        hcRows{first + r, a} := DnumToNum(v / 1000000);
      ENDFOR
    ENDFOR
    hcLoadCrc := hcCrcRaw(hcLoadCrc, hcRxPay, 6, 24 * count);
    hcRowsIn := first + count;
    hcAck;
  ENDPROC

  PROC hcLoadStops()
    VAR num first;
    VAR num count;
    VAR num row;
    UnpackRawBytes hcRxPay, 1, first \IntX:=UINT;
    UnpackRawBytes hcRxPay, 3, count \IntX:=USINT;
    IF count < 1 OR count > HC_STOPS_PER_CHUNK OR first + count > hcNStops THEN
      hcSendNak hcRxSeq, NAK_BAD_PAYLOAD, "stops out of range";
      RETURN;
    ENDIF
    IF first + count <= hcStopsIn THEN
      hcAck;
      RETURN;
    ENDIF
    IF first <> hcStopsIn OR hcRowsIn < hcNRows THEN
      hcSendNak hcRxSeq, NAK_BAD_PAYLOAD, "stops out of order or before the rows";
      RETURN;
    ENDIF
    FOR s FROM 1 TO count DO
      UnpackRawBytes hcRxPay, 4 + 4 * (s - 1), row \IntX:=UDINT;
      IF row >= hcNRows THEN
        hcSendNak hcRxSeq, NAK_BAD_PAYLOAD, "stop row beyond the rows";
        RETURN;
      ENDIF
      hcStops{first + s} := row + 1;
    ENDFOR
    hcLoadCrc := hcCrcRaw(hcLoadCrc, hcRxPay, 4, 4 * count);
    hcStopsIn := first + count;
    hcAck;
  ENDPROC

  PROC hcLoadEnd()
    VAR dnum id;
    VAR num row;
    UnpackRawBytes hcRxPay, 1, id \IntX:=UDINT;
    IF hcRowsIn < hcNRows OR hcStopsIn < hcNStops THEN
      hcSendNak hcRxSeq, NAK_REFUSED, "rows or stops missing";
      RETURN;
    ENDIF
    IF id <> hcLoadId OR id <> hcTrajectoryId() THEN
      hcSendNak hcRxSeq, NAK_REFUSED, "trajectory id does not match the data";
      RETURN;
    ENDIF
    row := hcRowOnPath();
    IF row < 1 THEN
      hcState := ST_FAULT;
      hcFault := FLT_OFF_PATH;
      hcSendNak hcRxSeq, NAK_REFUSED, "the arm is not on the trajectory: jog it home";
      RETURN;
    ENDIF
    hcTrajId := id;
    hcLoaded := TRUE;
    hcPos := row;
    hcAtStop := -1;
    IF hcNStops > 0 THEN
      FOR s FROM 1 TO hcNStops DO
        IF hcStops{s} = row AND hcAtStop < 0 hcAtStop := s - 1;
      ENDFOR
    ENDIF
    hcState := ST_IDLE;
    IF hcAtStop >= 0 hcState := ST_IN_POSITION;
    hcAck;
  ENDPROC

  ! CRC-32 of the rows (int32 LE micro-degrees) followed by the stop rows (u32 LE),
  ! accumulated over the payloads as they arrived (hcLoadRows, hcLoadStops)
  FUNC dnum hcTrajectoryId()
    VAR dnum c;
    c := BitXOrDnum(hcLoadCrc, HC_CRC32_INIT);
    IF c = 0 c := 1;
    RETURN c;
  ENDFUNC

  FUNC num hcRowOnPath()
    VAR jointtarget j;
    VAR num e;
    j := CJointT();
    FOR r FROM 1 TO hcNRows DO
      e := Max(Abs(hcRows{r, 1} - j.robax.rax_1), Abs(hcRows{r, 2} - j.robax.rax_2));
      e := Max(e, Max(Abs(hcRows{r, 3} - j.robax.rax_3), Abs(hcRows{r, 4} - j.robax.rax_4)));
      e := Max(e, Max(Abs(hcRows{r, 5} - j.robax.rax_5), Abs(hcRows{r, 6} - j.robax.rax_6)));
      IF e <= HC_ON_PATH_TOL_DEG RETURN r;
    ENDFOR
    RETURN 0;
  ENDFUNC

  ! --- motion ------------------------------------------------------------------
  PROC hcMoveToStop()
    VAR num k;
    UnpackRawBytes hcRxPay, 1, k \IntX:=UINT;
    IF NOT hcLoaded THEN
      hcSendNak hcRxSeq, NAK_NOT_LOADED, "no trajectory loaded";
    ELSEIF k > hcNStops THEN
      hcSendNak hcRxSeq, NAK_BAD_PAYLOAD, "no such stop";
    ELSEIF k = hcNStops THEN
      hcStartMove hcNRows, k;
    ELSE
      hcStartMove hcStops{k + 1}, k;
    ENDIF
  ENDPROC

  PROC hcStartMove(num row, num stop)
    IF hcState = ST_ESTOP OR hcState = ST_FAULT THEN
      hcSendNak hcRxSeq, NAK_REFUSED, "fault latched; RESET first";
      RETURN;
    ENDIF
    hcTargetRow := row;
    hcTargetStop := stop;
    hcAtStop := -1;
    hcState := ST_MOVING;
    hcAck;
  ENDPROC

  ! One via-point per call: every HC_ROW_STEP-th row with a zone, timed with \T
  ! so the motion keeps the planner's timing; the target row as a fine point.
  ! Every move is \Conc (the program keeps serving the link: a STOP waits for
  ! at most one queued move); in position once the arm is at the target row.
  PROC hcMotionStep()
    VAR num next;
    VAR num dir;
    VAR jointtarget jt;
    IF hcState <> ST_MOVING RETURN;
    IF hcPos = hcTargetRow THEN
      IF hcArmAtRow(hcTargetRow) THEN
        hcAtStop := hcTargetStop;
        hcTargetStop := -1;
        hcState := ST_IN_POSITION;
      ENDIF
      RETURN;
    ENDIF
    dir := 1;
    IF hcTargetRow < hcPos dir := -1;
    next := hcPos + dir * HC_ROW_STEP;
    IF dir * (next - hcTargetRow) >= 0 next := hcTargetRow;
    jt := CJointT();
    jt.robax := [hcRows{next, 1}, hcRows{next, 2}, hcRows{next, 3},
                 hcRows{next, 4}, hcRows{next, 5}, hcRows{next, 6}];
    IF next = hcTargetRow THEN
      MoveAbsJ \Conc, jt \NoEOffs, v1000 \T:=Abs(next - hcPos) * hcDt, fine, tool0;
    ELSE
      MoveAbsJ \Conc, jt \NoEOffs, v1000 \T:=HC_ROW_STEP * hcDt, z5, tool0;
    ENDIF
    hcPos := next;
  ENDPROC

  ! whether every joint is within HC_IN_POS_TOL_DEG of row r
  FUNC bool hcArmAtRow(num r)
    VAR jointtarget j;
    j := CJointT();
    RETURN Abs(hcRows{r, 1} - j.robax.rax_1) <= HC_IN_POS_TOL_DEG
       AND Abs(hcRows{r, 2} - j.robax.rax_2) <= HC_IN_POS_TOL_DEG
       AND Abs(hcRows{r, 3} - j.robax.rax_3) <= HC_IN_POS_TOL_DEG
       AND Abs(hcRows{r, 4} - j.robax.rax_4) <= HC_IN_POS_TOL_DEG
       AND Abs(hcRows{r, 5} - j.robax.rax_5) <= HC_IN_POS_TOL_DEG
       AND Abs(hcRows{r, 6} - j.robax.rax_6) <= HC_IN_POS_TOL_DEG;
  ENDFUNC

  PROC hcHalt(num state, num fault)
    IF hcState = ST_MOVING THEN
      StopMove;
      ClearPath;
      StartMove;
      hcPos := hcNearestRow(hcPos);
    ENDIF
    hcState := state;
    hcFault := fault;
    hcTargetStop := -1;
    hcAtStop := -1;
  ENDPROC

  ! the row nearest the arm's joints among the last via-points issued (at most
  ! five concurrent moves and the final one are queued)
  FUNC num hcNearestRow(num around)
    VAR jointtarget j;
    VAR num best;
    VAR num bestErr := 1E9;
    VAR num e;
    j := CJointT();
    best := around;
    FOR r FROM Max(1, around - 6 * HC_ROW_STEP) TO Min(hcNRows, around + 6 * HC_ROW_STEP) DO
      e := Abs(hcRows{r, 1} - j.robax.rax_1) + Abs(hcRows{r, 2} - j.robax.rax_2)
           + Abs(hcRows{r, 3} - j.robax.rax_3) + Abs(hcRows{r, 4} - j.robax.rax_4)
           + Abs(hcRows{r, 5} - j.robax.rax_5) + Abs(hcRows{r, 6} - j.robax.rax_6);
      IF e < bestErr THEN
        bestErr := e;
        best := r;
      ENDIF
    ENDFOR
    RETURN best;
  ENDFUNC

  PROC hcWatchdog()
    IF hcState = ST_MOVING AND ClkRead(hcLinkClock) > HC_LINK_TIMEOUT_S THEN
      hcHalt ST_STOPPED, FLT_LINK_LOST;
    ENDIF
  ENDPROC

  ! Event routine (connect to the system event RESET / POWER_ON): an emergency
  ! stop ends program execution; after the restart STATUS reports it.
  PROC hcOnEstop()
    hcEstopLatched := TRUE;
  ENDPROC
ENDMODULE
