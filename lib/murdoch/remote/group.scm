;;;; The lab's multicast group: datagrams that prove the lab's key and
;;;; cannot be replayed, and beacons that keep the live set.
;;
;; The thesis wished for IP multicast (§1.2).  With (delivery multicast
;; GROUP [PORT]) in the lab file, every address space joins the group.
;; A datagram is 64 hex digits of HMAC-SHA256 under the lab's key over
;; "mcast:" and the text, then the text: (SENDER SEQUENCE BODY).  SEQUENCE
;; is the sender's clock when it sent, in microseconds since 1970, and
;; grows with every datagram of a sender, so a restarted sender does not go
;; back.  A recorded datagram cannot be replayed, to any receiver: one
;; drops a datagram
;;   - whose sequence it has passed (it heard that one, or a later one);
;;   - sent before it started (it joined late, or restarted, since);
;;   - sent more than frame-timeout ago (the window a datagram may take,
;;     and the most that the hosts' clocks may differ).
;; BODY is one of
;;   (beacon UID HOST PORT)         every beacon period: here I am
;;   (call ID KIND PROC ARGS)       KIND run or apply, as on a connection
;;
;; Beacons are live membership without a registry (docs/architecture.md,
;; "Delivery and membership"); the period grows with the lab beyond 16,
;; as RTCP's report interval grows with a session.
;;
;; The group knows nothing of what a call means.  start-group! is handed
;; the procedure that serves the group's calls, as Chibi's run-net-server
;; is handed its handler: serving (delivery.scm) imports the group, and
;; the group imports nothing above it.

;; The lab's group as this address space joined it, made by start-group!;
;; #f while the lab's delivery is broadcast.  Global: one per process,
;; shared by its senders, its listener and its beacons.
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

;; Global: an address space is in at most one group, its lab's.
(define *group* #f)

(define max-datagram 60000)
(define lab-beacons-per-second 16)

;;> Joins \var{lab}'s multicast group when the lab's delivery is
;;> multicast, and starts its beacons and a thread that applies
;;> \var{serve} to \scheme{receive-call}: a procedure of no arguments that
;;> waits for the group's next datagram and returns the group-call it
;;> carries, or #f when it carried none (a beacon, or our own datagram
;;> looped back).  It raises for a datagram
;;> that is not authentic or not fresh.  Only one thread at a time may
;;> call it: the datagram is read into one buffer.
(define (start-group! lab serve)
  ;; (multicast GROUP [PORT]) or (broadcast)
  (let ((delivery (lab-setting lab 'delivery)))
    (when (eq? (car delivery) 'multicast)
      (let ((group (cadr delivery))
            (port (if (pair? (cddr delivery))
                      (car (cddr delivery))
                      (lab-planned-port lab 'multicast))))
        (set! *group*
              (make-group (open-multicast-socket group port
                                                 (aspace-host (local-aspace)))
                          (get-address-info group port)
                          ;; One buffer (docs/speed.md, What Chibi charges).
                          (make-bytevector 65536)
                          (datagram-head (aspace-uid (local-aspace)))
                          (lab-setting lab 'frame-timeout) (wall-microseconds)
                          0 (make-mutex 'sequence) (make-hash-table eq?)
                          (make-hash-table eq?) (make-mutex 'last-heard)))
        (spawn (lambda () (serve receive-call)) 'multicast)
        (spawn send-beacons 'beacon)))))

;;> How publish and request reach the lab: \scheme{multicast} or
;;> \scheme{broadcast}.
(define (delivery-mode) (if *group* 'multicast 'broadcast))

;;; Sending

;; The sequence of the next datagram: two threads sending at once take
;; two, else the receivers would drop the second as a replay.
(define (next-sequence!)
  (with-lock (group-sequence-lock *group*)
    (lambda ()
      (let ((sequence (max (+ (group-sequence *group*) 1) (wall-microseconds))))
        (group-sequence-set! *group* sequence)
        sequence))))

;;> Sends \var{body} to the group; #f when it is too large for a datagram.
(define (send-datagram! body)
  (let* ((sequence (next-sequence!))
         (text (call-with-output-string
                 (lambda (o)
                   (write-simple (list (local-aspace-uid) sequence body) o))))
         (bytes (datagram-bytes text)))
    (and (<= (bytevector-length bytes) max-datagram)
         (begin (send (group-socket *group*) bytes 0 (group-address *group*)) #t))))

(define (beacon-seconds)
  (max 1 (/ (length (known-uids)) (inexact lab-beacons-per-second))))

;; A beacon each period, and out of the live set with whoever has not
;; sent one for three.
(define (send-beacons)
  (let ((me (local-aspace)))
    (send-datagram! (make-message 'beacon (aspace-uid me) (aspace-host me)
                                  (aspace-port me))))
  (let ((now (monotonic-seconds))
        (period (beacon-seconds)))
    (for-each (lambda (uid)
                (if (< (with-lock (group-last-heard-lock *group*)
                         (lambda ()
                           (hash-table-ref/default (group-last-heard *group*) uid now)))
                       (- now (* 3 period)))
                    (note-unreachable! uid)))
              (known-uids))
    (thread-sleep! period))
  (send-beacons))

;;; Receiving
;;
;; On the path of every call that comes by the group: no let, match,
;; with-lock or hash-table-ref/default (docs/speed.md, What Chibi charges).

(define (receive-call)
  (let ((n (receive! (group-socket *group*) (group-buffer *group*))))
    (and (>= n 0)
         (not (datagram-from? (group-buffer *group*) n (group-own-head *group*)))
         (heard (open-datagram (group-buffer *group*) n)))))

;; The call that datagram d carries, once its sender is heard from.  Our
;; own datagrams, looped back, are dropped before (receive-call), unread:
;; a multicast requester read its every call back.  One that names us
;; otherwise written (only a holder of the key could send it) is dropped
;; here.  Our own uid thus has no last-heard, and never leaves the live set.
(define (heard d)
  (lock! (group-last-heard-lock *group*))
  (hash-table-set! (group-last-heard *group*) (datagram-sender d) (monotonic-seconds))
  (unlock! (group-last-heard-lock *group*))
  (and (not (eq? (datagram-sender d) (local-aspace-uid)))
       (datagram-call (datagram-sender d) (datagram-body d))))

;; The (SENDER SEQUENCE BODY) of an authentic, fresh datagram, the first n
;; bytes of buffer.
(define (open-datagram buffer n)
  (fresh-datagram (check-datagram (open-datagram-text buffer n))))

(define (fresh-datagram d)
  (check-fresh (datagram-sender d) (datagram-sequence d))
  (hash-table-set! (group-last-sequence *group*) (datagram-sender d)
                   (datagram-sequence d))
  d)

;; A datagram's fields, as check-datagram passed them.
(define (datagram-sender d) (car d))
(define (datagram-sequence d) (cadr d))
(define (datagram-body d) (list-ref d 2))

(define (check-fresh sender sequence)
  (cond ((<= sequence (cell-value (hash-table-cell (group-last-sequence *group*)
                                                   sender #f)
                                  0))
         (frame-fail "replayed or out of order"))
        ((< sequence (group-started *group*))
         (frame-fail "sent before this address space started"))
        ((< sequence (- (wall-microseconds) (* 1000000 (group-window *group*))))
         (frame-fail "older than frame-timeout"))))

;;> A call that came by the group: from address space \var{sender}, its
;;> \var{id} there, \var{kind} run or apply, and its procedure and
;;> arguments encoded.
(define-record-type group-call
  (make-group-call sender id kind proc-code args-code)
  group-call?
  (sender group-call-sender)
  (id group-call-id)
  (kind group-call-kind)
  (proc-code group-call-proc-code)
  (args-code group-call-args-code))

;; A beacon brings its sender (back) into the live set; a call is the
;; caller's to serve.
(define (datagram-call sender body)
  (group-call-of sender (check-message body '(beacon call) "a beacon or a call")))

;; A call's fields taken by their places in the wire's table of messages
;; (wire/frame.scm).
(define (group-call-of sender message)
  (if (eq? (car message) 'call)
      (make-group-call sender (message-id message) (list-ref message 2)
                       (list-ref message 3) (list-ref message 4))
      (beacon-heard! sender message)))

(define (beacon-heard! sender beacon)
  (match beacon
    (('beacon uid host port)
     (learn-aspace! (make-aspace uid host port))
     (note-reachable! sender)
     #f)))
