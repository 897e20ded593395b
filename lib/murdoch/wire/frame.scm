;;;; The wire: frames, and the one table of message kinds (thesis §3.3.2).
;;
;; Procedures travel between address spaces as S-expressions
;; (sendable.scm), in frames.  Each connection is opened by the address
;; space that calls; the callee only answers on it.  Every frame is a
;; netstring whose payload is 64 hex digits of HMAC-SHA256 followed by an
;; S-expression:
;;
;;   MAC = HMAC(key, NONCE ":" COUNT ":" S-EXPRESSION)
;;
;; where NONCE is the one the receiving side chose for this connection and
;; COUNT numbers the frames sent in this direction from 1.  A recorded frame
;; is thus worthless on another connection or at another place in this one.
;;
;;  1. Caller -> callee: (hello UID HOST PORT NONCE), MAC'd with nonce
;;     "hello" and count 0.  HOST and PORT say where the caller listens.
;;  2. Callee -> caller: (welcome UID NONCE), MAC'd with the caller's nonce
;;     and count 0.  From here on each side uses the other's nonce.
;;  3. Caller -> callee, any number, pipelined:
;;       (run ID PROC ARGS)    apply in a worker thread, answer at once
;;       (apply ID PROC ARGS)  apply, answer with the value (serve.scm says
;;                             which thread applies it)
;;       (answer ID KIND VALUE)  not answered: the answer to call ID of a
;;                             multicast datagram from the callee
;;       (abandon ID)          not answered: the caller gave up waiting for
;;                             apply ID; the thread running it stops at its
;;                             next remote call or robot command (abandon.scm)
;;     PROC, ARGS and VALUE are encoded values (sendable.scm); ID is the
;;     caller's, or for an answer the datagram sender's.
;;  4. Callee -> caller, in any order:
;;       (ack ID)  (value ID VALUE)  (error ID MESSAGE)
;;
;; A multicast datagram (delivery.scm) is 64 hex digits of HMAC-SHA256
;; over "mcast:" and its text, then the text: (SENDER SEQUENCE BODY), BODY
;; a beacon or a call.
;;
;; A frame that is not a netstring, fails its MAC, or is not one of the
;; kinds in message-kinds closes its connection after one log line; the
;; address space and its other connections carry on.  Nothing is evaluated
;; before its MAC checks.

;;; The message kinds

(define (anything? x) #t)
(define (answer-kind? x) (memq x '(ack value error)))
(define (call-kind? x) (memq x '(run apply)))

;; Every message: its kind, then its fields, each with its check.  The
;; datagram has no kind word of its own; the rest begin with theirs.
(define message-kinds
  `((hello (uid ,symbol?) (host ,string?) (port ,exact-integer?)
           (nonce ,string?))
    (welcome (uid ,symbol?) (nonce ,string?))
    (run (id ,exact-integer?) (proc ,anything?) (args ,list?))
    (apply (id ,exact-integer?) (proc ,anything?) (args ,list?))
    (answer (id ,exact-integer?) (kind ,answer-kind?) (value ,anything?))
    (abandon (id ,exact-integer?))
    (ack (id ,exact-integer?))
    (value (id ,exact-integer?) (value ,anything?))
    (error (id ,exact-integer?) (message ,string?))
    (datagram (sender ,symbol?) (sequence ,exact-integer?) (body ,pair?))
    (beacon (uid ,symbol?) (host ,string?) (port ,exact-integer?))
    (call (id ,exact-integer?) (kind ,call-kind?) (proc ,anything?)
          (args ,list?))))

(define (message-fields kind)
  (cond ((assq kind message-kinds) => cdr)
        (else (error "no such message kind" kind))))

;;> A message of \var{kind} with \var{fields}, which must be as many as
;;> the table says.
(define (make-message kind . fields)
  (if (not (= (length fields) (length (message-fields kind))))
      (error "wrong number of fields for a message" kind fields))
  (cons kind fields))

;;> \var{message} when it is one of \var{kinds} and each field passes its
;;> check; else a protocol error, "expected WHAT".
(define (check-message message kinds what)
  (if (not (and (pair? message) (memq (car message) kinds)
                (fields-pass? (cdr message) (message-fields (car message)))))
      (frame-fail "expected " what))
  message)

;;> A datagram's (SENDER SEQUENCE BODY), checked as check-message does.
(define (check-datagram d)
  (if (not (fields-pass? d (message-fields 'datagram)))
      (protocol-fail "datagram" "not a datagram"))
  d)

;;> The id of \var{message}, of a kind whose first field is its id (all
;;> but hello, welcome, datagram and beacon), once check-message passed it.
(define (message-id message) (cadr message))

(define (fields-pass? values fields)
  (cond ((null? fields) (null? values))
        ((pair? values) (and ((cadr (car fields)) (car values))
                             (fields-pass? (cdr values) (cdr fields))))
        (else #f)))

;;; Frames

;; The wire's state: the key and limits of the lab this process joined,
;; read once by start-wire!, before the first frame, since every frame
;; reads them.  Global: every connection and datagram speaks for that lab.
(define-record-type wire
  (make-wire key max-frame max-depth)
  wire?
  (key wire-key)
  (max-frame wire-max-frame)
  (max-depth wire-max-depth))

;; Global: the lab's key and limits, for every frame of the process.
(define *wire* #f)

;;> Makes the frames and datagrams of this process those of \var{lab}:
;;> its key, max-frame and max-depth.  Once, before any frame.
(define (start-wire! lab)
  (set! *wire* (make-wire (lab-key lab) (lab-setting lab 'max-frame)
                          (lab-setting lab 'max-depth))))

;; Each connection writes its frames' text to a string port of its own,
;; emptied before each frame, so that a write that failed half-way leaves
;; nothing behind (its writer holds the connection's lock).
(define (frame-text text-port message)
  (reset-output-string! text-port)
  (write-simple message text-port)
  (within-max-frame (get-output-string text-port)))

;; The receiver would refuse a frame past max-frame and close the
;; connection, failing the calls on it that had nothing to do with this one.
(define (within-max-frame text)
  (if (> (+ 64 (string-size text)) (wire-max-frame *wire*))
      (error (string-append "the message is larger than the lab's max-frame, "
                            (number->string (max-frame)) " bytes")))
  text)

;;> The text of the message (\var{kind} ID FIELD ...) for \var{fields}
;;> but its id, for \scheme{spliced-text}: a call to many peers differs only
;;> by its id, so its text is written once, not once a peer.
(define (message-without-id kind fields)
  (cons (cdr (assq kind kind-heads)) (fields-text fields)))

;; "(KIND " for each kind of the table, made once.
(define kind-heads
  (map (lambda (k) (cons (car k) (string-append "(" (symbol->string (car k)) " ")))
       message-kinds))

;; The text " FIELD ...)" of fields, written to one string port for every
;; call, under its lock (docs/speed.md).  Encoded values are plain data, whose writing
;; raises nothing, so the lock needs no dynamic-wind.
(define fields-port (open-output-string))
(define fields-lock (make-mutex 'fields-text))

(define (fields-text fields)
  (lock! fields-lock)
  (reset-output-string! fields-port)
  (for-each (lambda (field)
              (write-char #\space fields-port)
              (write-simple field fields-port))
            fields)
  (write-char #\) fields-port)
  (unlocked fields-lock (get-output-string fields-port)))

;;> The text of the message that \var{parts}, from message-without-id,
;;> and \var{id} make: the text frame-text would give.  The id's digits by
;;> fixnum->decimal: Chibi's number->string and symbol->string take a
;;> microsecond each, as long as writing the whole message.
(define (spliced-text parts id)
  (within-max-frame (string-append (car parts) (fixnum->decimal id) (cdr parts))))

(define (write-frame! out text nonce count)
  (hmac-sha256-write! (wire-key *wire*) text (list nonce ":" count ":") out))

(define (send-frame! out text-port nonce count message)
  (write-frame! out (frame-text text-port message) nonce count)
  (flush-output-port out))

;; A frame that breaks the protocol raises a protocol remote-error; its
;; connection closes.
(define (frame-fail . parts)
  (apply protocol-fail "frame" parts))

;; The next frame's message, or an eof object when the peer closed.  A
;; bad frame raises (see fault-message), and the connection's one handler
;; closes it (no handler per frame: docs/speed.md, What Chibi charges).
(define (read-frame in nonce count)
  (let ((payload (read-netstring in (wire-max-frame *wire*))))
    (if (eof-object? payload)
        payload
        (open-frame payload nonce count))))

;;> The message of a frame whose netstring's payload is \var{payload}, the
;;> count'th from the side whose nonce is given; raises as read-frame.
(define (open-frame payload nonce count)
  (parse-message
   (authentic-text payload (bytevector-length payload)
                  (list nonce ":" count ":"))))

;;> The lab's max-frame: the most bytes a netstring's payload may hold.
(define (max-frame) (wire-max-frame *wire*))

;; The text after the MAC in the first end bytes of bytes, once the MAC is
;; that of the list parts followed by the text.
(define (authentic-text bytes end parts)
  (or (hmac-sha256-open (wire-key *wire*) bytes end parts)
      (frame-fail "bad MAC")))

;; Read by Chibi's own reader (docs/speed.md), which recurses without
;; bound and makes cycles of datum labels: so a message that nests deeper
;; than twice max-depth (its envelope, and a value one level too deep for
;; decoding to refuse), or has a label, is a protocol violation.
(define (parse-message text)
  (if (not (nests-within? text (* 2 (wire-max-depth *wire*))))
      (frame-fail "nests deeper than twice max-depth, or has a datum label"))
  (let ((in (open-input-string text)))
    (whole-datum in (read-datum in))))

;; The message read from in, when it is all there is.  A procedure of its
;; own, not a let* inside parse-message: see docs/speed.md.
(define (whole-datum in message)
  (cond ((eof-object? message) (frame-fail "empty message"))
        ((not (eof-object? (peek-char in))) (frame-fail "trailing data"))
        (else message)))

;; Whether e says that the other side broke the protocol.
(define (protocol-fault? e)
  (or (remote-protocol-error? e) (read-error? e)))

;; What was wrong with a frame or datagram that raised e, for the log.
(define (fault-message e)
  (if (read-error? e)
      (string-append "unreadable message: " (error-message e))
      (error-message e)))

;; The one log line of a connection closed for e.
(define (log-fault peer e)
  (log-warn "connection with " peer " closed: " (fault-message e)))

;;; Datagrams

;;> The bytes of a datagram carrying \var{text}, with its MAC.
(define (datagram-bytes text)
  (string->utf8 (hmac-sha256-sign (wire-key *wire*) text '("mcast:"))))

;;> The message of the authentic datagram in the first n bytes of buffer.
(define (open-datagram-text buffer n)
  (parse-message (authentic-text buffer n '("mcast:"))))

;;> The bytes that begin the text of a datagram from \var{uid}, for
;;> datagram-from?.
(define (datagram-head uid)
  (string->utf8 (string-append "(" (call-with-output-string
                                     (lambda (o) (write-simple uid o)))
                               " ")))

;;> Whether the datagram in the first \var{n} bytes of \var{buffer} says,
;;> unchecked, that it comes from the sender whose datagram-head is
;;> \var{head}: a look before its MAC is checked and its text read.
(define (datagram-from? buffer n head)
  (bytes-at? buffer 64 n head 0))

(define (bytes-at? buffer at n head i)
  (cond ((= i (bytevector-length head)) #t)
        ((>= (+ at i) n) #f)
        ((= (bytevector-u8-ref buffer (+ at i)) (bytevector-u8-ref head i))
         (bytes-at? buffer at n head (+ i 1)))
        (else #f)))
