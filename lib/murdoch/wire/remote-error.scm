;;;; The remote errors: one family, a kind for each way a call fails.
;;
;; Its irritants: the target's uid (#f for a peer not yet known), what was
;; called or read, and the message.  The kinds:
;;   timed-out     no answer within the timeout (connecting included)
;;   unreachable   no connection, or it was lost or refused
;;   raised        the procedure raised an error at the callee
;;   protocol      a peer broke the wire protocol: a bad netstring, MAC,
;;                 message or welcome
(define remote-error-kinds '(timed-out unreachable raised protocol))

(define (remote-error kind uid what message)
  (raise (make-exception kind
                         (if uid
                             (string-append "remote-apply on "
                                            (symbol->string uid) " failed")
                             (string-append "protocol violation: " message))
                         (list uid what message) #f #f)))

;;> Raises the protocol error, of \var{parts}, for a frame from an unnamed peer.
(define (protocol-fail what . parts)
  (remote-error 'protocol #f what (apply string-append parts)))

;;> Raised by remote-apply and remote-run! for an error in the target, a
;;> lost connection or a timeout: one of the four kinds below.
(define (remote-error? e)
  (and (exception? e) (memq (exception-kind e) remote-error-kinds) #t))

(define (remote-error-of-kind? kind e)
  (and (exception? e) (eq? (exception-kind e) kind)))

;;> A remote-error for a call that had no answer within its timeout.
(define (remote-timeout-error? e) (remote-error-of-kind? 'timed-out e))

;;> A remote-error for a target that could not be reached, or was lost.
(define (remote-unreachable-error? e) (remote-error-of-kind? 'unreachable e))

;;> A remote-error for a procedure that raised an error in the target.
(define (remote-raised-error? e) (remote-error-of-kind? 'raised e))

;;> A remote-error for a peer that broke the wire protocol.
(define (remote-protocol-error? e) (remote-error-of-kind? 'protocol e))

;;> The uid of the address space a remote-error concerns, or #f.
(define (remote-error-uid e) (car (exception-irritants e)))

;;> What went wrong, as a string.
(define (remote-error-message e) (car (cddr (exception-irritants e))))

;;> What \var{e}, any raised object, says, as one line: a remote error's
;;> own message, else condition-message's.
(define (error-message e)
  (if (and (remote-error? e) (not (stack-guard-tripped? (current-thread))))
      (remote-error-message e)
      (condition-message e)))

;;> As error-message, a remote error's message after its uid, as
;;> \scheme{"praline: car: not a pair ()"}, for an answer or an ERROR line.
(define (error-message-naming e)
  (let ((uid (and (remote-error? e) (remote-error-uid e))))
    (if uid
        (string-append (symbol->string uid) ": " (error-message e))
        (error-message e))))
