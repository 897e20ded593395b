;;;; Workers: the threads that run what nobody waits for.

;;> Starts thunk in a new thread named name, which received code cannot
;;> stop (make-guarded-thread); if thunk raises, the log says so.
(define (spawn thunk name)
  (thread-start! (make-guarded-thread (lambda () (run-logged thunk name)) name)))

(define (run-logged thunk name)
  (guard (e (#t (log-warn name ": " (error-message e))))
    (thunk)))

;; A remote-run!'s procedure runs in a thread of its own, since its caller
;; does not wait for it (an apply runs in the thread that read it: see
;; serve.scm).  A thread that is done waits a while for the next procedure
;; instead of ending (docs/speed.md, What Chibi charges).
;; Global: one pool for the process, which every reader hands runs to.
(define *idle-workers* '())             ; mailboxes of waiting workers
(define *workers-lock* (make-mutex 'workers))
(define worker-idle-seconds 10)

;; Runs thunk in a worker; if it raises, the log says so.
(define (run-in-worker thunk)
  (hand-over! (idle-worker) thunk))

(define (hand-over! idle thunk)
  (if idle
      (mailbox-put! idle thunk)
      (spawn (lambda () (work thunk)) 'worker)))

;; The mailbox of a waiting worker, taken from the pool, or #f.  Here and
;; in next-job the pool's lock is taken by lock!, not with-lock: nothing
;; under it raises (docs/speed.md, What Chibi charges).
(define (idle-worker)
  (lock! *workers-lock*)
  (let ((mb (and (pair? *idle-workers*) (car *idle-workers*))))
    (if mb (set! *idle-workers* (cdr *idle-workers*)))
    (unlock! *workers-lock*)
    mb))

;; One handler for the worker's whole life, entered again only after a job
;; raised (docs/speed.md).  The worker waits for each next job on one
;; mailbox of its own.
(define (work job)
  (let ((mb (make-mailbox)))
    (let serve ((job job))
      (guard (e (#t (flush-call-ports!)
                    (log-warn "worker: " (error-message e))
                    (let ((next (next-job mb)))
                      (if next (serve next)))))
        (run-jobs job mb)))))

;; Runs job, then each next one that comes to mailbox mb.
(define (run-jobs job mb)
  (job)
  (let ((next (next-job mb)))
    (if next (run-jobs next mb))))

;; The next job for this worker, or #f when none came within
;; worker-idle-seconds.  Its mailbox mb is in the pool only while it
;; waits, so no caller can put to it while it is emptied.
(define (next-job mb)
  (mailbox-empty! mb)
  (lock! *workers-lock*)
  (set! *idle-workers* (cons mb *idle-workers*))
  (unlock! *workers-lock*)
  (or (mailbox-take mb (+ (monotonic-seconds) worker-idle-seconds) no-job)
      ;; Timed out; but a caller may have taken this worker meanwhile, in
      ;; which case its procedure is on the way.
      (and (not (with-lock *workers-lock*
                  (lambda ()
                    (and (memq mb *idle-workers*)
                         (begin (set! *idle-workers*
                                      (delete mb *idle-workers* eq?))
                                #t)))))
           ;; The job is on its way; an hour is only a bound.
           (mailbox-take mb (+ (monotonic-seconds) 3600) no-job))))

(define (no-job) #f)
