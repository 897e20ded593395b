;;;; The wire: frames, and the one table of message kinds (thesis §3.3.2).
;;
;; Procedures travel between address spaces as S-expressions
;; (code/sendable.scm) in frames, on connections opened by the caller.  A
;; frame is a netstring: 64 hex digits of HMAC-SHA256, then an S-expression,
;;   MAC = HMAC(key, NONCE ":" COUNT ":" S-EXPRESSION)
;; NONCE the receiver's for this connection, COUNT the frame's number in
;; this direction from 1: a recorded frame is worthless anywhere else.
;;  1. Caller -> callee: (hello UID HOST PORT NONCE), nonce "hello", count
;;     0; HOST and PORT say where the caller listens.
;;  2. Callee -> caller: (welcome UID NONCE), the caller's nonce, count 0.
;;     From here on each side uses the other's nonce.
;;  3. Caller -> callee, any number, pipelined:
;;       (run ID PROC ARGS)      apply in a worker thread, answer at once
;;       (apply ID PROC ARGS)    apply, answer with the value
;;       (answer ID KIND VALUE)  unanswered: the answer to the callee's
;;                               multicast call ID
;;       (abandon ID)            unanswered: the caller gave up on apply ID,
;;                               which stops at its next remote call or
;;                               robot command (code/abandon.scm)
;;     PROC, ARGS and VALUE are encoded values; ID is the caller's, or for
;;     an answer the datagram sender's.
;;  4. Callee -> caller, in any order: (ack ID) (value ID VALUE) (error ID MESSAGE)
;; A datagram (remote/group.scm) is the HMAC over "mcast:" and its text,
;; then the text.  A frame that is not a netstring, fails its MAC, or is
;; not in message-kinds closes its connection after one log line; nothing
;; is evaluated before its MAC checks.

;;; The message kinds

(define answer-kinds '(ack value error))
(define call-kinds '(run apply))
(define (anything? x) #t)
(define (answer-kind? x) (memq x answer-kinds))
(define (call-kind? x) (memq x call-kinds))

;; Every message: its kind, then its fields, each with its check (the
;; datagram has no kind word).
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

;; Each kind's field count and checks, from the table once, since every
;; message made and every frame read is checked (docs/speed.md): (KIND
;; COUNT CHECK ...), each check as fields-pass? (plain-read.c) takes it.
(define check-codes
  `((,anything? . 0) (,exact-integer? . 1) (,symbol? . 2) (,string? . 3) (,list? . 4)
    (,pair? . 5) (,answer-kind? . ,answer-kinds) (,call-kind? . ,call-kinds)))

(define kind-checks
  (map (lambda (k)
         (cons (car k) (cons (length (cdr k))
                             (map (lambda (f) (cdr (assq (cadr f) check-codes)))
                                  (cdr k)))))
       message-kinds))

(define-syntax checks-of
  (syntax-rules () ((_ kind) (checks-in (assq kind kind-checks) kind))))

;; No cond =>, whose let makes a closure (docs/speed.md).
(define (checks-in entry kind)
  (if entry (cdr entry) (error "no such message kind" kind)))

;;> A message of \var{kind} with \var{fields}, as many as the table says.
(define (make-message kind . fields)
  (if (= (length fields) (car (checks-of kind)))
      (cons kind fields)
      (error "wrong number of fields for a message" kind fields)))

;;> \var{message} when it is one of \var{kinds} with good fields, else a protocol error.
(define (check-message message kinds what)
  (if (and (pair? message) (memq (car message) kinds)
           (fields-pass? (cdr message) (cdr (checks-of (car message)))))
      message
      (frame-fail "expected " what)))

;;> A datagram's (SENDER SEQUENCE BODY), checked as check-message does.
(define (check-datagram d)
  (if (fields-pass? d (cdr (checks-of 'datagram)))
      d
      (protocol-fail "datagram" "not a datagram")))

;;> The id of \var{message} (all kinds but hello, welcome, datagram, beacon).
(define (message-id message) (car (cdr message))) ; cadr is a call

;;> The field named \var{name} of \var{message}, a checked message, as
;;> the table names it.
(define (message-field message name)
  (let loop ((fields (cdr (assq (car message) message-kinds)))
             (values (cdr message)))
    (cond ((null? fields) (error "no such field in a message" (car message) name))
          ((eq? (caar fields) name) (car values))
          (else (loop (cdr fields) (cdr values))))))

;;; Frames

(define-record-type wire
  (make-wire key max-frame max-depth)
  wire?
  (key wire-key)
  (max-frame wire-max-frame)
  (max-depth wire-max-depth))

;; The node's wire part: the lab's key and limits, read by every frame.
(define-syntax the-wire (syntax-rules () ((_) (node-wire *node*))))

;;> Makes this process's frames those of its lab, once, before any frame.
(define (start-wire!)
  (node-wire-set! (this-node) (make-wire (lab-key (current-lab)) (setting 'max-frame)
                                         (setting 'max-depth))))

;; A connection's frame text goes to its own string port, emptied before
;; each frame, so a write that failed half-way leaves nothing behind.
(define (frame-text text-port message)
  (reset-output-string! text-port)
  (write-simple message text-port)
  (within-max-frame (get-output-string text-port)))

;; The receiver would close the connection, failing calls unrelated to this one.
(define (within-max-frame text)
  (if (> (+ 64 (string-size text)) (wire-max-frame (the-wire)))
      (too-large))
  text)

(define (too-large)
  (error (string-append "the message is larger than the lab's max-frame, "
                        (number->string (max-frame)) " bytes")))

;;> The text of the message (\var{kind} ID FIELD ...) but its id, for
;;> \scheme{spliced-text}: a call to many peers is written once.
(define (message-without-id kind fields)
  (cons (cdr (assq kind kind-heads)) (fields-text fields)))

(define kind-heads
  (map (lambda (k) (cons (car k) (string-append "(" (symbol->string (car k)) " ")))
       message-kinds))

;; Global: the text " FIELD ...)" of every call's fields is written to one
;; string port, under its lock (docs/speed.md); writing plain data raises
;; nothing, so no dynamic-wind.
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

;;> The text of the message that \var{parts}, from message-without-id, and
;;> \var{id} make, as frame-text would give it (fast: docs/speed.md).
(define (spliced-text parts id)
  (within-max-frame (string-append (car parts) (fixnum->decimal id) (cdr parts))))

(define (write-frame! out text nonce count)
  (hmac-sha256-write! (wire-key (the-wire)) text (cons nonce count) out))

;;> Writes \var{message}'s frame to \var{out} by way of \var{text-port}, as
;;> write-frame! of its frame-text, making no string of the text but when
;;> it outgrows the port's buffer (docs/speed.md).
(define (write-message! out text-port message nonce count)
  (reset-output-string! text-port)
  (write-simple message text-port)
  (written-text out text-port nonce count
                (hmac-sha256-write-text! (wire-key (the-wire)) text-port
                                         (cons nonce count) out
                                         (wire-max-frame (the-wire)))))

(define (written-text out text-port nonce count written)
  (cond ((eq? written 'too-large) (too-large))
        ((eq? written #f)
         (write-frame! out (within-max-frame (get-output-string text-port))
                       nonce count))))

(define (send-frame! out text-port nonce count message)
  (write-message! out text-port message nonce count)
  (flush-output-port out))

;; A frame that breaks the protocol raises; its connection closes.
(define (frame-fail . parts)
  (apply protocol-fail "frame" parts))

;; The next frame's message, or an eof object; a bad frame raises.
(define (read-frame in nonce count)
  (let ((payload (read-netstring in (wire-max-frame (the-wire)))))
    (if (eof-object? payload)
        payload
        (open-frame payload nonce count))))

;; The text after the MAC in bytes, once the MAC is that of parts and the text.
(define-syntax authentic-text
  (syntax-rules ()
    ((_ bytes end parts)
     (mac-checked (hmac-sha256-open (wire-key (the-wire)) bytes end parts)))))

;;> The message of the count'th frame, \var{payload}, from the side whose nonce is given.
(define (open-frame payload nonce count)
  (parse-message
   (authentic-text payload (bytevector-length payload)
                  (cons nonce count))))

;;> The lab's max-frame: the most bytes a netstring's payload may hold.
(define (max-frame) (wire-max-frame (the-wire)))

;; No or, whose let makes a closure (docs/speed.md).
(define (mac-checked text) (if text text (frame-fail "bad MAC")))

;; A plain message is read in C (plain-read.c), which answers not-plain
;; for anything else.  Chibi's reader (docs/speed.md) recurses without
;; bound and makes cycles of datum labels, so for it nesting deeper than
;; twice max-depth (the envelope, and a value one level too deep to
;; decode), or a label, is refused; the C reader refuses the same depth.
(define (parse-message text)
  (read-message text (* 2 (wire-max-depth (the-wire)))))

;; No let, whose closure each frame would make (docs/speed.md).
(define (read-message text limit)
  (plain-else-read text limit (plain-message text limit not-plain)))

(define not-plain (list 'not-plain))

(define (plain-else-read text limit plain)
  (if (eq? plain not-plain) (read-not-plain text limit) plain))

(define (read-not-plain text limit)
  (if (nests-within? text limit)
      (let ((in (open-input-string text)))
        (whole-datum in (read-datum in)))
      (frame-fail "nests deeper than twice max-depth, or has a datum label")))

;; The message read from in, when it is all there is (docs/speed.md).
(define (whole-datum in message)
  (cond ((eof-object? message) (frame-fail "empty message"))
        ((not (eof-object? (peek-char in))) (frame-fail "trailing data"))
        (else message)))

(define (protocol-fault? e)
  (or (remote-protocol-error? e) (read-error? e)))

(define (fault-message e)
  (if (read-error? e)
      (string-append "unreadable message: " (error-message e))
      (error-message e)))

(define (log-fault peer e)
  (log-warn "connection with " peer " closed: " (fault-message e)))

;;; Datagrams

;;> The bytes of a datagram carrying \var{text}, with its MAC.
(define (datagram-bytes text)
  (string->utf8 (hmac-sha256-sign (wire-key (the-wire)) text '("mcast:"))))

;;> The message of the authentic datagram in the first n bytes of buffer.
(define (open-datagram-text buffer n)
  (parse-message (authentic-text buffer n '("mcast:"))))

;;> The bytes that begin the text of a datagram from \var{uid}.
(define (datagram-head uid)
  (string->utf8 (string-append "(" (call-with-output-string
                                     (lambda (o) (write-simple uid o)))
                               " ")))

;;> Whether \var{buffer}'s datagram says, unchecked, it comes from \var{head}'s sender.
(define (datagram-from? buffer n head)
  (bytes-at? buffer 64 n head 0))

(define (bytes-at? buffer at n head i)
  (cond ((= i (bytevector-length head)) #t)
        ((>= (+ at i) n) #f)
        ((= (bytevector-u8-ref buffer (+ at i)) (bytevector-u8-ref head i))
         (bytes-at? buffer at n head (+ i 1)))
        (else #f)))
