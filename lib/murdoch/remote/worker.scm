;;;; Workers: the threads that run what nobody waits for.

;;> Starts thunk in a thread named name, guarded from received code; logs a raise.
(define (spawn thunk name)
  (thread-start! (make-guarded-thread (lambda () (run-logged thunk name)) name)))

;;> (\var{thunk}); if it raises, its error logged after \var{name}, \var{default} or #f.
(define (run-logged thunk name . default)
  (guard (e (#t (log-warn name ": " (error-message e)) (and (pair? default) (car default))))
    (thunk)))

;; Global: one pool for the process, which every reader hands runs to.  A
;; remote-run! runs in a worker as nobody waits for it; an idle worker
;; waits a while for the next job instead of ending (docs/speed.md).
(define *idle-workers* '())             ; mailboxes of waiting workers
(define *workers-lock* (make-mutex 'workers))
(define worker-idle-seconds 10)

(define (run-in-worker thunk)
  (hand-over! (idle-worker) thunk))

(define (hand-over! idle thunk)
  (if idle
      (mailbox-put! idle thunk)
      (spawn (lambda () (work thunk)) 'worker)))

;; The mailbox of a waiting worker, taken from the pool, or #f (lock!: nothing raises).
(define (idle-worker)
  (lock! *workers-lock*)
  (let ((mb (and (pair? *idle-workers*) (car *idle-workers*))))
    (if mb (set! *idle-workers* (cdr *idle-workers*)))
    (unlock! *workers-lock*)
    mb))

;; One handler for the worker's whole life (docs/speed.md), and one mailbox.
(define (work job)
  (let ((mb (make-mailbox)))
    (let serve ((job job))
      (guard (e (#t (flush-call-ports!)
                    (log-warn "worker: " (error-message e))
                    (let ((next (next-job mb)))
                      (if next (serve next)))))
        (run-jobs job mb)))))

(define (run-jobs job mb)
  (job)
  (let ((next (next-job mb)))
    (if next (run-jobs next mb))))

;; The next job, or #f after worker-idle-seconds; mb is pooled only while waiting.
(define (next-job mb)
  (mailbox-empty! mb)
  (lock! *workers-lock*)
  (set! *idle-workers* (cons mb *idle-workers*))
  (unlock! *workers-lock*)
  (job-or-late mb (mailbox-take mb (+ (monotonic-seconds) worker-idle-seconds) no-job)))

;; No or, whose let makes a closure a job (docs/speed.md).
(define (job-or-late mb job)
  (if job job (late-job mb)))

;; Timed out; but a caller may have taken this worker meanwhile.
(define (late-job mb)
  (and (not (with-lock *workers-lock*
              (lambda ()
                (and (memq mb *idle-workers*)
                     (begin (set! *idle-workers* (delete mb *idle-workers* eq?))
                            #t)))))
       (mailbox-take mb (+ (monotonic-seconds) 3600) no-job)))

(define (no-job) #f)
