;;;; Delivery: how publish and request reach the whole lab (thesis §4.1).
;;;; The thesis sent to each machine in turn; under (delivery multicast
;;;; ...) publish and the query phase of requests are one datagram to the
;;;; group, answered over TCP; a message too large goes the broadcast way.


;;> remote-apply-all to every live address space (here too), by one
;;> datagram when delivery is multicast and it fits, else to each in turn.
(define (broadcast-apply proc . args) (broadcast 'apply proc args))

;;> remote-run-all! to every live address space, as broadcast-apply.
(define (broadcast-run! proc . args) (broadcast 'run proc args))

(define (broadcast kind proc args)
  (check-not-abandoned (if (eq? kind 'run) "broadcast-run!" "broadcast-apply"))
  (let ((c (new-call kind proc args)))
    (or (multicast-call-all c)
        (send-all (live-aspaces) c))))

;;; Multicast

;; send-all by multicast when it is on and c fits, else #f.
(define (multicast-call-all c)
  (and (eq? (delivery-mode) 'multicast)
       (let* ((g (make-gathering))
              (expected (expect-answers! (datagram-others) g))
              (id (car expected))
              (waiting (cdr expected)))
         (define (forget!) (forget-answers! id))
         (define sent (monotonic-seconds))
         (if (send-datagram! (make-message 'call id (call-kind c) (call-proc-code c)
                                           (call-args-code c)))
             (let* ((here (capture (local-aspace-uid)
                                   (lambda () (local-call (call-kind c) (call-proc c)
                                                          (call-args c)))))
                    (deadline (+ (monotonic-seconds) (call-seconds c))))
               (undo-on-raise forget!
                              (lambda () (await-answers g waiting deadline)))
               (forget!)
               (cons here
                     (capture-each pending-call-uid
                                   (lambda (p)
                                     (make-result (pending-call-uid p) #t
                                                  (datagram-answer-value p c sent)))
                                   waiting)))
             (begin (forget!) #f)))))

;; What p's answer says, as answer-value has it, but for a member heard
;; after the call was sent that did not answer: it stays in the live set.
;; It was not yet listening when the call went (a lab starting); out of
;; the live set, it would still take the calls that follow, unheard: a
;; request's reservations left to their lease.
(define (datagram-answer-value p c sent)
  (if (and (not (pending-call-answer p)) (heard-since? (pending-call-uid p) sent))
      (no-answer (pending-call-uid p) (call-proc c) (call-seconds c))
      (answer-value p c)))

;;; Serving the group's calls
;; As a connection (serve.scm): the listener applies, the janitor relieves it.

;; Serves call, unless #f, which answer answers (no let: docs/speed.md).
(define (serve-group-call r call answer)
  (if call
      (serve-call r (make-served-call (uid->aspace (group-call-sender call))
                                      (group-call-id call) (group-call-kind call)
                                      (group-call-proc-code call)
                                      (group-call-args-code call) answer))))

;;> Serves the calls that \scheme{(receive-call)} gives, the group's; a
;;> call's error is its answer, any other failure drops the datagram.
(define (serve-group receive-call)
  (let ((s (new-serving! "the multicast group" #f #f #f)))
    (serving-read-on-set! s (lambda () (serve-group-calls s receive-call)))
    (read-as-reader s (serving-read-on s))))

;; Serves the group's calls while this thread is its listener (read-calls).
(define (serve-group-calls s receive-call)
  (define (answer c kind value)
    (send-datagram-answer! (served-call-caller c) (served-call-id c) kind value))
  (define (read-on r)
    (serve-group-call r (receive-call) answer)
    (if (reader? s) (read-on r)))
  (read-calls s read-on
              (lambda (c e)
                (guard (e2 (#t (log-warn "an answer was lost: "
                                         (fault-message e2))))
                  (reply! c 'error (error-message-naming e))))
              (lambda (e) (log-warn "datagram dropped: " (fault-message e)))))
