;;;; Delivery: how publish and request reach the whole lab (thesis §4.1).
;;
;; The thesis sent each message to every machine in turn, for want of
;; broadcast in Kali (§4.1), and wished for IP multicast (§1.2).  With
;; (delivery multicast GROUP [PORT]) in the lab file, publish and the query
;; phase of request and request-exclusive go out as one datagram to the
;; lab's group; each address space answers the sender point to point over
;; its TCP connection, with an answer frame (send-datagram-answer!), so
;; the semantics are the broadcast's.  A message too large for a datagram
;; goes the broadcast way.
;;
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
;; Beacons are live membership without a registry: an address space not
;; heard from for three beacon periods leaves the live set, and its next
;; beacon brings it back.  The period is a second in a lab of up to 16
;; address spaces and grows with the lab beyond (as RTCP's report interval
;; grows with a session), so that the lab as a whole sends about 16
;; beacons a second: with every one beaconing each second, each address
;; space of a lab of N would receive N a second, and the lab N squared.


;;; Broadcast

;;> remote-apply-all to every live address space (here too): by one
;;> multicast datagram when the lab's delivery is multicast and the message
;;> fits, else to each in turn.
(define (broadcast-apply proc . args) (broadcast 'apply proc args))

;;> remote-run-all! to every live address space, as broadcast-apply.
(define (broadcast-run! proc . args) (broadcast 'run proc args))

(define (broadcast kind proc args)
  (check-not-abandoned (if (eq? kind 'run) "broadcast-run!" "broadcast-apply"))
  (let ((seconds (current-timeout))
        (proc-code (encode proc (lab-environment) "the procedure"))
        (args-code (encode-arguments args)))
    (or (multicast-call-all kind proc-code args-code proc args seconds)
        (send-all (map uid->aspace (live-uids)) kind proc args
                  proc-code args-code seconds))))

;;; Multicast

(define *multicast* #f)                 ; (socket . group address), or #f
(define *sequence* 0)                   ; of the last datagram sent
(define *sequence-lock* (make-mutex 'sequence))
(define *started* 0)                    ; microseconds, at start-multicast!
(define *last-sequence* (make-hash-table eq?))  ; sender -> sequence
(define *last-heard* (make-hash-table eq?))     ; uid -> monotonic-seconds
(define *last-heard-lock* (make-mutex 'last-heard))
(define max-datagram 60000)
(define lab-beacons-per-second 16)

(define (beacon-seconds)
  (max 1 (/ (length (known-uids)) (inexact lab-beacons-per-second))))

(define (start-multicast! lab)
  ;; (multicast GROUP [PORT]) or (broadcast)
  (let ((delivery (lab-setting lab 'delivery)))
    (when (eq? (car delivery) 'multicast)
      (let ((group (cadr delivery))
            (port (if (pair? (cddr delivery))
                      (car (cddr delivery))
                      (+ (lab-port-base lab) 149))))
        (set! *multicast*
              (cons (open-multicast-socket group port (aspace-host (local-aspace)))
                    (get-address-info group port)))
        (set! *started* (wall-microseconds))
        (spawn listen-to-group 'multicast)
        (spawn send-beacons 'beacon)))))

;;> How publish and request reach the lab: \scheme{multicast} or
;;> \scheme{broadcast}.
(define (delivery-mode) (if *multicast* 'multicast 'broadcast))

;;; Sending

;; The sequence of the next datagram: two threads sending at once take
;; two, else the receivers would drop the second as a replay.
(define (next-sequence!)
  (with-lock *sequence-lock*
    (lambda ()
      (set! *sequence* (max (+ *sequence* 1) (wall-microseconds)))
      *sequence*)))

;; Sends body to the group; #f when it is too large for a datagram.
(define (send-datagram! body)
  (let* ((sequence (next-sequence!))
         (text (call-with-output-string
                 (lambda (o)
                   (write-simple (list (local-aspace-uid) sequence body) o))))
         (bytes (datagram-bytes text)))
    (and (<= (bytevector-length bytes) max-datagram)
         (begin (send (car *multicast*) bytes 0 (cdr *multicast*)) #t))))

(define (send-beacons)
  (let ((me (local-aspace)))
    (send-datagram! (make-message 'beacon (aspace-uid me) (aspace-host me)
                                  (aspace-port me))))
  (let ((now (monotonic-seconds))
        (period (beacon-seconds)))
    (for-each (lambda (uid)
                (if (< (with-lock *last-heard-lock*
                         (lambda ()
                           (hash-table-ref/default *last-heard* uid now)))
                       (- now (* 3 period)))
                    (note-unreachable! uid)))
              (known-uids))
    (thread-sleep! period))
  (send-beacons))
;; call-all over multicast, when it is on and the message fits a
;; datagram: answers call-all's list, or #f to send the broadcast way.
(define (multicast-call-all kind proc-code args-code proc args seconds)
  (and *multicast*
       (let* ((others (remove (lambda (uid) (eq? uid (local-aspace-uid)))
                              (live-uids)))
              (waiting (map (lambda (uid) (cons uid (make-mailbox))) others))
              (id (expect-answers! waiting)))
         (define (forget!) (forget-answers! id))
         (if (send-datagram! (make-message 'call id kind proc-code args-code))
             (let* ((here (capture (local-aspace-uid)
                                   (lambda () (local-call kind proc args))))
                    (deadline (+ (monotonic-seconds) seconds))
                    (there (capture-each
                            car
                            (lambda (w)
                              (list (car w) #t
                                    (await-answer (car w) (cdr w) deadline
                                                  seconds proc (lambda () #f))))
                            waiting)))
               (forget!)
               (cons here there))
             (begin (forget!) #f)))))


;;; Receiving
;;
;; The group is read as a connection is (serve.scm):
;; its listener applies a call itself, and the janitor gives the group a
;; new listener when an apply runs long.

(define (listen-to-group)
  (let ((s (new-serving! "the multicast group" #f #f #f)))
    ;; Datagrams are received into one buffer: a new 64 KB bytevector for
    ;; each, dozens a second, cost more than serving them.
    (serving-read-on-set! s (lambda ()
                              (receive-datagrams s (make-bytevector 65536))))
    (read-as-reader s (serving-read-on s))))

;; Serves datagrams while this thread is the group's listener (see
;; read-calls): a call's error is its answer; any other failure drops the
;; datagram.
(define (receive-datagrams s buffer)
  (define (read-on call)
    (let ((n (receive! (car *multicast*) buffer)))
      (if (>= n 0)
          (serve-datagram s call (open-datagram buffer n))))
    (if (reader? s) (read-on call)))
  (read-calls s read-on
              (lambda (to+id e)
                (guard (e2 (#t (log-warn "an answer was lost: "
                                         (fault-message e2))))
                  (send-datagram-answer! (car to+id) (cdr to+id) 'error
                                          (error-message e))))
              (lambda (e) (log-warn "datagram dropped: " (fault-message e)))))

;; The (SENDER SEQUENCE BODY) of an authentic, fresh datagram, the first n
;; bytes of buffer.
(define (open-datagram buffer n)
  (let ((d (check-datagram (open-datagram-text buffer n))))
    (match d
      ((sender sequence body)
       (check-fresh sender sequence)
       (hash-table-set! *last-sequence* sender sequence)
       d))))

(define (check-fresh sender sequence)
  (cond ((<= sequence (hash-table-ref/default *last-sequence* sender 0))
         (frame-fail "replayed or out of order"))
        ((< sequence *started*)
         (frame-fail "sent before this address space started"))
        ((< sequence (- (wall-microseconds) (* 1000000 (frame-timeout))))
         (frame-fail "older than frame-timeout"))))

(define (serve-datagram s call d)
  (match d
    ((sender sequence body)
     (with-lock *last-heard-lock*
       (lambda () (hash-table-set! *last-heard* sender (monotonic-seconds))))
     (if (not (eq? sender (local-aspace-uid)))   ; else our own, looped back
         (serve-body s call sender
                     (check-message body '(beacon call) "a beacon or a call"))))))

;; A beacon brings its sender (back) into the live set.  A call runs as
;; serve-call runs one, and is answered to its sender over TCP; an error
;; is answered by receive-datagrams.
(define (serve-body s call sender body)
  (match body
    (('beacon uid host port)
     (learn-aspace! (make-aspace uid host port))
     (note-reachable! sender))
    (('call id kind proc-code args-code)
     (let ((to (uid->aspace sender)))
       (serve-call s call (cons to id) kind proc-code args-code
                   (lambda (kind value)
                     (send-datagram-answer! to id kind value)))))))
