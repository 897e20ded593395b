;;;; The lab's multicast group (thesis §1.2's wish): datagrams that prove
;;;; the lab's key and cannot be replayed, and beacons that keep the live set.
;;
;; With (delivery multicast GROUP [PORT]) every address space joins the
;; group.  A datagram is 64 hex digits of HMAC-SHA256 under the lab's key
;; over "mcast:" and the text, then the text: (SENDER SEQUENCE BODY).
;; SEQUENCE is the sender's clock in microseconds since 1970, growing with
;; each datagram, so a restarted sender does not go back.  A receiver drops
;; a datagram whose sequence it has passed, sent before it started, or sent
;; more than frame-timeout ago (the most a datagram may take, and the hosts'
;; clocks differ).  BODY is one of
;;   (beacon UID HOST PORT)         every beacon period: here I am
;;   (call ID KIND PROC ARGS)       KIND run or apply, as on a connection
;; Beacons keep membership without a registry (docs/architecture.md); their
;; period grows beyond 16, as RTCP's does.  start-group! is handed the
;; procedure that serves calls, so the group imports nothing above it.

;; The lab's group as joined here, #f under broadcast; shared by its threads.
(define-record-type group
  (make-group socket address buffer own-head window started sequence sequence-lock
              last-sequence last-heard last-heard-lock)
  group?
  (socket group-socket)
  (address group-address)               ; the group's address and port
  (buffer group-buffer)                 ; each datagram is received into it
  (own-head group-own-head)             ; datagram-head of our own uid
  (window group-window)                 ; the lab's frame-timeout, seconds
  (started group-started)               ; (wall-microseconds) at start-group!
  (sequence group-sequence group-sequence-set!) ; of the last datagram sent
  (sequence-lock group-sequence-lock)
  (last-sequence group-last-sequence)   ; sender -> sequence
  (last-heard group-last-heard)         ; uid -> monotonic-seconds
  (last-heard-lock group-last-heard-lock))

;; The node's group part: an address space is in at most one group, its lab's.
(define-syntax the-group (syntax-rules () ((_) (node-group *node*))))

(define max-datagram 60000)
(define lab-beacons-per-second 16)

;;> Joins the lab's multicast group when delivery is multicast, starting
;;> beacons and a thread applying \var{serve} to \scheme{receive-call}, which
;;> returns the next datagram's group-call or #f and raises for one not
;;> authentic or fresh (one thread at a time: one buffer).
(define (start-group! serve)
  ;; (multicast GROUP [PORT]) or (broadcast)
  (let ((delivery (setting 'delivery)))
    (when (eq? (car delivery) 'multicast)
      (let ((group (cadr delivery))
            (port (if (pair? (cddr delivery))
                      (car (cddr delivery))
                      (lab-planned-port (current-lab) 'multicast))))
        (node-group-set!
         (this-node)
         (make-group (open-multicast-socket group port (aspace-host (local-aspace)))
                     (get-address-info group port)
                     ;; One buffer (docs/speed.md, What Chibi charges).
                     (make-bytevector 65536)
                     (datagram-head (aspace-uid (local-aspace)))
                     (setting 'frame-timeout) (wall-microseconds)
                     0 (make-mutex 'sequence) (make-hash-table eq?)
                     (make-hash-table eq?) (make-mutex 'last-heard)))
        (spawn (lambda () (serve receive-call)) 'multicast)
        (spawn send-beacons 'beacon)))))

;;> How publish and request reach the lab: \scheme{multicast} or \scheme{broadcast}.
(define (delivery-mode) (if (and *node* (the-group)) 'multicast 'broadcast))

;;; Sending

;; The next datagram's sequence.  Under the sequence's lock, with the
;; send: receivers drop a datagram whose sequence they have passed, and
;; two threads that took theirs in one order and sent in the other lost
;; the first (8 threads publishing at once lost some of 80).
(define (next-sequence!)
  (let ((sequence (max (+ (group-sequence (the-group)) 1) (wall-microseconds))))
    (group-sequence-set! (the-group) sequence)
    sequence))

;;> Sends \var{body} to the group; #f when it is too large for a datagram.
(define (send-datagram! body)
  (with-lock (group-sequence-lock (the-group))
    (lambda ()
      (let* ((text (call-with-output-string
                     (lambda (o)
                       (write-simple (list (local-aspace-uid) (next-sequence!) body) o))))
             (bytes (datagram-bytes text)))
        (and (<= (bytevector-length bytes) max-datagram)
             (begin (send (group-socket (the-group)) bytes 0 (group-address (the-group)))
                    #t))))))

(define (beacon-seconds)
  (max 1 (/ (length (known-uids)) (inexact lab-beacons-per-second))))

;; A beacon each period; out of the live set goes whoever missed three.
(define (send-beacons)
  (let ((me (local-aspace)))
    (send-datagram! (make-message 'beacon (aspace-uid me) (aspace-host me)
                                  (aspace-port me))))
  (let ((now (monotonic-seconds))
        (period (beacon-seconds)))
    (for-each (lambda (uid)
                (if (< (last-heard uid now) (- now (* 3 period)))
                    (note-unreachable! uid)))
              (known-uids))
    (thread-sleep! period))
  (send-beacons))

;; When uid's last datagram came, or default if none did.
(define (last-heard uid default)
  (with-lock (group-last-heard-lock (the-group))
    (lambda () (hash-table-ref/default (group-last-heard (the-group)) uid default))))

;;> Whether a datagram from \var{uid} came at \var{t}, a
;;> (monotonic-seconds), or after.
(define (heard-since? uid t)
  (let ((heard (last-heard uid #f)))
    (and heard (>= heard t))))

;;; Receiving
;;
;; On every group call's path: no let, match or with-lock (docs/speed.md).

(define (receive-call)
  (let ((n (receive! (group-socket (the-group)) (group-buffer (the-group)))))
    (and (>= n 0)
         (not (datagram-from? (group-buffer (the-group)) n
                              (group-own-head (the-group))))
         (heard (open-datagram (group-buffer (the-group)) n)))))

;; The call datagram d carries, once its sender is heard from.  Our own,
;; looped back, are dropped unread before (receive-call); one naming us
;; otherwise written is dropped here, so our uid never leaves the live set.
(define (heard d)
  (lock! (group-last-heard-lock (the-group)))
  (hash-table-set! (group-last-heard (the-group)) (datagram-sender d)
                   (monotonic-seconds))
  (unlock! (group-last-heard-lock (the-group)))
  (and (not (eq? (datagram-sender d) (local-aspace-uid)))
       (datagram-call (datagram-sender d) (datagram-body d))))

;; The (SENDER SEQUENCE BODY) of an authentic, fresh datagram in buffer.
(define (open-datagram buffer n)
  (fresh-datagram (check-datagram (open-datagram-text buffer n))))

(define (fresh-datagram d)
  (check-fresh (datagram-sender d) (datagram-sequence d))
  (hash-table-set! (group-last-sequence (the-group)) (datagram-sender d)
                   (datagram-sequence d))
  d)

(define (datagram-sender d) (car d))
(define (datagram-sequence d) (cadr d))
(define (datagram-body d) (list-ref d 2))

(define (check-fresh sender sequence)
  (cond ((<= sequence (cell-value (hash-table-cell (group-last-sequence (the-group))
                                                   sender #f)
                                  0))
         (frame-fail "replayed or out of order"))
        ((< sequence (group-started (the-group)))
         (frame-fail "sent before this address space started"))
        ((< sequence (- (wall-microseconds) (* 1000000 (group-window (the-group)))))
         (frame-fail "older than frame-timeout"))))

;;> A call that came by the group: sender, \var{id}, \var{kind}, procedure and arguments.
(define-record-type group-call
  (make-group-call sender id kind proc-code args-code)
  group-call?
  (sender group-call-sender)
  (id group-call-id)
  (kind group-call-kind)
  (proc-code group-call-proc-code)
  (args-code group-call-args-code))

;; A beacon brings its sender (back) into the live set; a call is served.
(define (datagram-call sender body)
  (group-call-of sender (check-message body '(beacon call) "a beacon or a call")))

;; By the places in wire/frame.scm's table of messages.
(define (group-call-of sender message)
  (if (eq? (car message) 'call)
      (make-group-call sender (message-id message) (list-ref message 2)
                       (list-ref message 3) (list-ref message 4))
      (beacon-heard! sender message)))

(define (beacon-heard! sender beacon)
  (learn-aspace! (make-aspace (message-field beacon 'uid) (message-field beacon 'host)
                              (message-field beacon 'port)))
  (note-reachable! sender)
  #f)
