;;;; Abandoned calls: a procedure stops when nobody waits for it any more.
;;;; The callee marks the thread of an abandoned call; since Chibi stops a
;;;; thread from outside wherever it is, maybe holding a lock, the thread
;;;; stops itself at its next robot command or remote call, or is woken
;;;; from a long wait by the procedure it gave with-wake-on-abandon.

;; Global: a caller gives up from its connection's thread, read in the marked one.
(define *abandoned* '())                ; the marked threads
(define *wakers* '())                   ; ((thread . wake) ...), innermost first
(define *abandoned-lock* (make-mutex 'abandoned))

;;> Marks \var{thread}, whose call its caller gave up; wakes it if need be.
(define (abandon-thread! thread)
  (let ((waker (with-lock *abandoned-lock*
                 (lambda ()
                   (if (not (memq thread *abandoned*))
                       (set! *abandoned* (cons thread *abandoned*)))
                   (assq thread *wakers*)))))
    (if waker ((cdr waker)))))

;;> Applies \var{thunk}, calling \var{wake} from another thread should this
;;> one be marked meanwhile; thunk checks its mark after wake is in place.
(define (with-wake-on-abandon wake thunk)
  (let ((waker (cons (current-thread) wake)))
    (dynamic-wind
     (lambda ()
       (with-lock *abandoned-lock* (lambda () (set! *wakers* (cons waker *wakers*)))))
     thunk
     (lambda ()
       (with-lock *abandoned-lock*
         (lambda () (set! *wakers* (delete waker *wakers* eq?))))))))

;;> Takes the mark off \var{thread}, whose call has ended.
(define (forget-abandoned! thread)
  (with-lock *abandoned-lock*
    (lambda () (set! *abandoned* (delete thread *abandoned* eq?)))))

;;> Whether the current thread runs a call that its caller gave up.
(define (abandoned?)
  (and (pair? *abandoned*) (memq (current-thread) *abandoned*) #t))

;;> Raises, in a thread marked abandoned, an error saying \var{who} was not done.
(define (check-not-abandoned who)
  (if (abandoned?)
      (raise (make-exception 'abandoned
                             (string-append who ": stopped, its caller gave up")
                             '() #f #f))))

;;> Whether \var{e} is the error that check-not-abandoned raises.
(define (abandoned-error? e)
  (and (exception? e) (eq? (exception-kind e) 'abandoned)))

;;> Runs \var{thunk} unmarked, then marks the thread again if it was: to tidy up.
(define (despite-abandonment thunk)
  (if (abandoned?)
      (let ((me (current-thread)))
        (dynamic-wind (lambda () (forget-abandoned! me))
                      thunk
                      (lambda () (abandon-thread! me))))
      (thunk)))
