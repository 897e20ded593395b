;;;; The robot's side of the task life cycle (life-cycle.scm): the components
;;;; of started tasks that run here, each watched for its poser's
;;;; heartbeats.


;; A component running here.
(define-record-type running
  (make-running id index poser thread heard)
  running?
  (id running-id)
  (index running-index)
  (poser running-poser)
  (thread running-thread)
  (heard running-heard running-heard-set!)    ; monotonic-seconds
  (over? running-over? running-over?-set!))

;; Global: the poser's calls (component-heartbeat! ...) find them by name.
(define *running* '())
(define *running-lock* (make-mutex 'running))

;;> Runs component \var{k} of task \var{id} here, for \var{poser}, which
;;> sends a heartbeat every \var{period} seconds: work is (PROC ARG ...).
;;> A robot failure comes back as (robot-failure WHY); any other condition
;;> is raised again once the component has left its dynamic extent.
(define (run-component id k poser period work)
  (hand-over-connection!)               ; its poser calls here meanwhile
  (let ((r (make-running id k poser (current-thread) (monotonic-seconds))))
    (running-over?-set! r #f)
    (with-lock *running-lock* (lambda () (set! *running* (cons r *running*))))
    (thread-start! (make-logged-thread (lambda () (watch-poser r period)) 'watch-poser))
    (let ((outcome
           (dynamic-wind
            (lambda () #f)
            (lambda ()
              ;; Every condition is caught: a guard that lets one through
              ;; raises it again inside the extent it left, and so runs the
              ;; component's own dynamic-wind before and after a second time.
              (guard (e ((robot-failure? e) (list 'robot-failure (error-message e)))
                        (#t (make-raised e)))
                (apply (car work) (cdr work))))
            (lambda ()
              (running-over?-set! r #t)
              (with-lock *running-lock*
                (lambda ()
                  (set! *running* (remove (lambda (x) (eq? x r)) *running*))))))))
      (if (raised? outcome) (raise (raised-condition outcome)) outcome))))

;; A condition that a component raised, held until it is outside.
(define-record-type raised
  (make-raised condition)
  raised?
  (condition raised-condition))

;; A trip connection closed or a stalled base: the robot, not the task,
;; failed.
(define (robot-failure? e)
  (and (trip-error? e) (memq (trip-error-code e) '(closed stalled)) #t))

;; No ghosts, with a margin: a component stops on its robot once its
;; poser has been silent for orphan-periods heartbeat periods, looked at
;; every quarter period, so by 2.25 periods after the last heartbeat the
;; robot heard; its poser declares the robot lost only when no heartbeat
;; was answered for lost-periods (life-cycle.scm), and the robot heard that
;; heartbeat before its answer reached the poser.  The stale copy has
;; stopped 1.75 periods before the poser can start another: one full
;; period, and more, for a loaded robot that is late to look.
(define orphan-periods 2)
(define lost-periods 4)

;; Stops r when its poser is silent for orphan-periods.
(define (watch-poser r period)
  (thread-sleep! (/ period 4))
  (cond ((running-over? r) #t)
        ((> (- (monotonic-seconds) (running-heard r)) (* orphan-periods period))
         (log-warn "the poser " (running-poser r) " of " (running-id r)
                   " is silent: component " (running-index r) " stops")
         (stop-running! r))
        (else (watch-poser r period))))

(define (stop-running! r)
  (abandon-thread! (running-thread r))
  (guard (e (#t #f)) (stop-base)))      ; when this address space has a robot

(define (find-running id k)
  (with-lock *running-lock*
    (lambda ()
      (find (lambda (r) (and (eq? (running-id r) id) (= (running-index r) k)))
            *running*))))

;;> A heartbeat from the poser of component \var{k} of task \var{id}:
;;> answers whether it runs here.
(define (component-heartbeat! id k)
  (let ((r (find-running id k)))
    (if r (running-heard-set! r (monotonic-seconds)))
    (and r #t)))

;;> Stops component \var{k} of task \var{id} here, as cancel-task asks.
(define (stop-component! id k)
  (let ((r (find-running id k)))
    (if r (stop-running! r))
    (and r #t)))

;; (ID INDEX POSER) for each component running here.
(define (components-running)
  (map (lambda (r) (list (running-id r) (running-index r) (running-poser r)))
       (with-lock *running-lock* (lambda () *running*))))
