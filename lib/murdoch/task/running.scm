;;;; The robot's side of the task life cycle (life-cycle.scm): components
;;;; running here, watched for their poser's heartbeats, and pose-task's,
;;;; which have none.  Each is listed, and remembered a while once ended,
;;;; so the live view sees how it ended though its poser be gone.


(define-record-type running
  (make-running id index poser thread started heard)
  running?
  (id running-id)
  (index running-index)
  (poser running-poser running-poser-set!)   ; a detached task's: its coordinator
  (thread running-thread)
  (started running-started)                   ; monotonic-seconds
  (heard running-heard running-heard-set!)    ; monotonic-seconds
  (over? running-over? running-over?-set!)
  (cancelled? running-cancelled? running-cancelled?-set!)) ; by its poser

;; The node's runs part: the components running here, which the poser's
;; calls (component-heartbeat! ...) find by name, and those ended here
;; (below); one lock over both.
(define-record-type runs
  (make-runs running ended lock)
  runs?
  (running runs-running runs-running-set!)
  (ended runs-ended runs-ended-set!)
  (lock runs-lock))

(define-syntax the-runs (syntax-rules () ((_) (node-runs *node*))))

(define (open-runs!) (node-runs-set! (this-node) (make-runs '() '() (make-mutex 'running))))

;;> Runs component \var{k} of task \var{id} here, for \var{poser}, which
;;> sends a heartbeat every \var{period} seconds: work is (PROC ARG ...).
;;> A robot failure comes back as (robot-failure WHY); any other condition
;;> is raised again once the component has left its dynamic extent.
(define (run-component id k poser period work)
  (hand-over-connection!)               ; its poser calls here meanwhile
  (run-listed id k poser work robot-failure?
              (lambda (r)
                (thread-start! (make-logged-thread (lambda () (watch-poser r period))
                                                   'watch-poser)))))

;;> Runs \var{thunk} here as component \var{k} of the task that
;;> pose-task posed from \var{poser} under the reservation name \var{id}:
;;> listed, as run-component's are, while it runs, and then among the
;;> components ended.  Answers what thunk answers, or raises what it
;;> raises.
(define (run-posed-component id k poser thunk)
  (run-listed id k poser (list thunk) (lambda (e) #f) (lambda (r) #f)))

;; Runs work listed as component k of id, watched as watch! sets it
;; going.
(define (run-listed id k poser work lost? watch!)
  (let* ((now (monotonic-seconds))
         (r (make-running id k poser (current-thread) now now))
         (outcome unfinished))
    (running-over?-set! r #f)
    (running-cancelled?-set! r #f)
    (let ((runs (the-runs)))
      (with-lock (runs-lock runs)
        (lambda () (runs-running-set! runs (cons r (runs-running runs))))))
    (watch! r)
    (dynamic-wind
     (lambda () #f)
     (lambda ()
       ;; Every condition is caught: a guard that lets one through raises
       ;; it again inside the extent it left, and so runs the component's
       ;; own dynamic-wind before and after a second time.
       (set! outcome (guard (e ((lost? e) (list 'robot-failure (error-message e)))
                               (#t (make-raised e)))
                       (apply (car work) (cdr work)))))
     (lambda ()
       (running-over?-set! r #t)
       (note-ended! r outcome)))
    (if (raised? outcome) (raise (raised-condition outcome)) outcome)))

;; The outcome of a component until it has one: it keeps it when run-listed
;; is left with no answer, by a continuation or thread-terminate!.
(define unfinished (list 'unfinished))

(define-record-type raised
  (make-raised condition)
  raised?
  (condition raised-condition))

;; A trip connection closed or a stalled base: the robot, not the task,
;; failed.
(define (robot-failure? e)
  (and (trip-error? e) (memq (trip-error-code e) '(closed stalled)) #t))

;; No ghosts: a component stops once its poser is silent for the lab's
;; orphan-periods (looked at every quarter period), well before the poser
;; declares the robot lost after lost-periods (life-cycle.scm) and may
;; start another: docs/tasks.md.

;;> How many silent heartbeat periods a component waits for its poser
;;> before it stops: the lab's orphan-periods.
(define (orphan-periods) (setting 'orphan-periods))

;;> How many silent heartbeat periods a poser waits before it declares a
;;> robot lost: the lab's lost-periods.
(define (lost-periods) (setting 'lost-periods))

(define (watch-poser r period)
  (thread-sleep! (/ period 4))
  (cond ((running-over? r) #t)
        ((> (- (monotonic-seconds) (running-heard r)) (* (orphan-periods) period))
         (log-warn "the poser " (running-poser r) " of " (running-id r)
                   " is silent: component " (running-index r) " stops")
         (stop-running! r))
        (else (watch-poser r period))))

(define (stop-running! r)
  (abandon-thread! (running-thread r))
  (guard (e (#t #f)) (stop-base)))      ; when this address space has a robot

(define (find-running id k)
  (with-lock (runs-lock (the-runs))
    (lambda ()
      (find (lambda (r) (and (eq? (running-id r) id) (= (running-index r) k)))
            (runs-running (the-runs))))))

;;> A heartbeat from the poser of component \var{k} of task \var{id}:
;;> answers whether it runs here.
(define (component-heartbeat! id k)
  (let ((r (find-running id k)))
    (if r (running-heard-set! r (monotonic-seconds)))
    (and r #t)))

;;> What a coordinator that took over a detached task calls where its
;;> component \var{k} of task \var{id} ran or runs: the component's
;;> heartbeats now come from \var{poser}, and the call answers, once it
;;> ends, what run-component would have answered its first coordinator,
;;> or raises what it raised.  One that ended lately answers at once; one
;;> not found here raises an error.
(define (await-component id k poser)
  (let ((r (find-running id k)))
    (when r
      (running-poser-set! r poser)
      (running-heard-set! r (monotonic-seconds))
      (release-call! (running-thread r))))
  (let wait ()
    (cond ((find-running id k) (thread-sleep! 0.05) (wait))
          ((find-ending id k)
           => (lambda (e)
                (let ((outcome (ending-outcome e)))
                  (cond ((eq? outcome unfinished)
                         (error "the component stopped with no answer" id k))
                        ((raised? outcome) (raise (raised-condition outcome)))
                        (else outcome)))))
          (else (error "no such component here" id k)))))

(define (find-ending id k)
  (with-lock (runs-lock (the-runs))
    (lambda ()
      (find (lambda (e)
              (let ((r (ending-running e)))
                (and (eq? (running-id r) id) (= (running-index r) k))))
            (runs-ended (the-runs))))))

;;> Stops component \var{k} of task \var{id} here, as cancel-task asks.
(define (stop-component! id k)
  (let ((r (find-running id k)))
    (when r
      (running-cancelled?-set! r #t)
      (stop-running! r))
    (and r #t)))

;;> (ID INDEX POSER) for each component running here.
(define (components-running)
  (map (lambda (r) (list (running-id r) (running-index r) (running-poser r)))
       (with-lock (runs-lock (the-runs)) (lambda () (runs-running (the-runs))))))

;;; The components ended here: the last kept-ended, newest first.  A
;;; component leaves the running list and joins this one under one lock,
;;; so a report reading both finds it in one or the other.

(define kept-ended 16)

(define-record-type ending
  (make-ending running at end outcome)
  ending?
  (running ending-running)
  (at ending-at)
  (end ending-end)
  (outcome ending-outcome))             ; what run-listed caught, for await-component

(define (note-ended! r outcome)
  (let ((entry (make-ending r (monotonic-seconds)
                            (if (and (running-cancelled? r)
                                     (not (eq? (car (end-of outcome)) 'done)))
                                '(cancelled)
                                (end-of outcome))
                            outcome))
        (runs (the-runs)))
    (with-lock (runs-lock runs)
      (lambda ()
        (runs-running-set! runs (remove (lambda (x) (eq? x r)) (runs-running runs)))
        (runs-ended-set! runs (let ((all (cons entry (runs-ended runs))))
                                (if (> (length all) kept-ended) (take all kept-ended) all)))))))

;; How a component ended: (done), (lost WHY), (failed WHY); note-ended!
;; makes it (cancelled) when its poser cancelled it.
(define (end-of outcome)
  (cond ((eq? outcome unfinished) '(failed "it stopped with no answer"))
        ((raised? outcome) (list 'failed (error-message (raised-condition outcome))))
        ((and (pair? outcome) (eq? (car outcome) 'robot-failure))
         (list 'lost (cadr outcome)))
        (else '(done))))

;;> The components that ended here, the last sixteen, newest first, each
;;> as (ID INDEX POSER STARTED ENDED END), read by the ended- procedures.
(define (components-ended)
  (let ((now (monotonic-seconds)))
    (map (lambda (e)
           (let ((r (ending-running e)))
             (list (running-id r) (running-index r) (running-poser r)
                   (- now (running-started r)) (- now (ending-at e)) (ending-end e))))
         (with-lock (runs-lock (the-runs)) (lambda () (runs-ended (the-runs)))))))

;;> The task id of \var{e}, an entry of components-ended.
(define (ended-id e) (car e))

;;> The component's number in \var{e}, an entry of components-ended.
(define (ended-index e) (cadr e))

;;> The seconds since the component of \var{e} started.
(define (ended-started e) (list-ref e 3))

;;> The seconds since the component of \var{e} ended.
(define (ended-ended e) (list-ref e 4))

;;> How the component of \var{e} ended: (done), (failed WHY), (lost WHY)
;;> or (cancelled).
(define (ended-end e) (list-ref e 5))
