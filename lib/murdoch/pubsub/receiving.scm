;;;; Receiving, part of (murdoch pubsub messaging): what the senders run in
;;;; each address space, (#t UID VALUE) or (#f UID), and the reservations.

(define (not-evaluated) (list #f (local-aspace-uid)))

;;> Evaluates a publication if it is addressed here.
(define (receive-publication topic uid proc args)
  (if (addressed-here? topic)
      (apply proc args))
  #t)

;;> Evaluates a request if it is addressed here: (#t uid result) or (#f uid).
(define (receive-request topic uid proc args)
  (if (addressed-here? topic)
      (list #t (local-aspace-uid) (apply proc args))
      (not-evaluated)))

;;> Reserves and promises, if addressed here and free: (#t uid promise) or (#f uid).
(define (receive-request-exclusive topiclist task-name uid proc args)
  (promise-for (reserve! (car topiclist) (cadr topiclist) task-name uid)
               proc args))

;;> The shared counterpart of receive-request-exclusive.
(define (receive-request-non-exclusive topics task-name uid proc args)
  (promise-for (reserve-shared! topics task-name) proc args))

;;> What request-components runs in each address space: (answer asked)
;;> for each component.
(define (receive-components components task-name uid)
  (map (lambda (c)
         (if (not (and (list? c) (= 4 (length c))))
             (error "receive-components: a component is (type layout proc askings)" c))
         (apply (lambda (type layout proc askings)
                  (let ((answer (cond ((not proc) (not-evaluated))
                                      ((eq? type 'exclusive)
                                       (receive-request-exclusive layout task-name uid proc '()))
                                      (else (receive-request (cadr layout) uid proc '())))))
                    (list answer (if (evaluated? answer) (map ask-here askings) '()))))
                c))
       components))

;; A component not addressed here, as most of a negotiation's are in most
;; of a lab, comes without its code, which is then not decoded (docs/speed.md).
(define (screen-components args)
  (if (and (list? args) (= 3 (length args)) (list? (car args)))
      (cons (map screened-component (car args)) (cdr args))
      args))

(define (screened-component c)
  (if (unaddressed-component? c) (list (car c) (cadr c) #f '()) c))

(define (unaddressed-component? c)
  (and (list? c) (= 4 (length c)) (layout? (cadr c))
       (not (if (eq? (car c) 'exclusive)
                (subscribed-to-layout? (car (cadr c)) (cadr (cadr c)))
                (addressed-here? (cadr (cadr c)))))))

(define (layout? x)
  (and (list? x) (= 2 (length x)) (every symbols? x)))

(define (symbols? x) (and (list? x) (every symbol? x)))

(screen-calls! receive-components screen-components)

;; An asking is user code: one raising costs only its answer (docs/speed.md).
(define (ask-here proc)
  (guard (e (#t (list #f (error-message e))))
    (list #t (proc))))

;;> Whether \var{a}, a candidate's answer to an asking, was a value.
(define (asked-ok? a) (car a))

;;> The value of \var{a}, a candidate's answer to an asking, or why none.
(define (asked-value a) (cadr a))

;;; Reservations

(define-record-type reservation
  (make-reservation task exclusive shared deadline state)
  reservation?
  (task reservation-task)
  (exclusive reservation-exclusive)     ; subjects held exclusively
  (shared reservation-shared)           ; subjects held for sharing
  (deadline reservation-deadline reservation-deadline-set!)
  (state reservation-state reservation-state-set!)) ; reserved running done

;; The lab's lease.
(define (lease) (setting 'lease))

;;> Starts freeing the subjects of promises unapplied for the lab's lease.
(define (start-leases!)
  (thread-start! (make-logged-thread lease-keeper 'lease-keeper)))

;; Free for task when free or held by task: one robot may promise two of a
;; task's components, and conflict resolution gives it at most one.
(define (free-for? s task)
  (let ((status (subscription-status s)))
    (or (null? status) (eq? status task))))

(define (not-held-by-another? s task)
  (let ((status (subscription-status s)))
    (or (null? status) (eq? status task) (eq? status 'shared))))

(define (hold! s status)
  (subscription-status-set! s status)
  (subscription-holds-set! s (+ 1 (subscription-holds s))))

;; Caller holds the lock.  The subscriptions, or #f if one is missing or not ok?.
(define (subscriptions-if topics ok?)
  (let ((subs (map find-subscription topics)))
    (and (every (lambda (s) (and s (ok? s))) subs) subs)))

;; Whether every subject is subscribed here by name, without the lock: most
;; of a lab lacks one, and is told so without the reservation's checks.
(define (subscribed-to-all? subjects)
  (or (null? subjects)
      (and (find-subscription (car subjects)) (subscribed-to-all? (cdr subjects)))))

(define (subscribed-to-layout? exclusive non-exclusive)
  (and (subscribed-to-all? exclusive) (subscribed-to-all? non-exclusive)))

(define (reserve! exclusive non-exclusive task uid)
  (and
   (subscribed-to-layout? exclusive non-exclusive)
   (with-subscriptions
     (lambda ()
       (let ((ex (and (not (and (pair? exclusive) (offered-elsewhere? uid)))
                      (subscriptions-if exclusive (lambda (s) (free-for? s task)))))
             (non (subscriptions-if non-exclusive
                                    (lambda (s) (not-held-by-another? s task)))))
         (and ex non
              (begin
                (for-each (lambda (s)
                            (hold! s task)
                            (add-subscription!
                             (in-use-subject (subscription-topic s))))
                          ex)
                (new-reservation! task exclusive '()))))))))

(define (reserve-shared! topics task)
  (and
   (subscribed-to-all? topics)
   (with-subscriptions
     (lambda ()
       (let ((subs (subscriptions-if
                    topics
                    (lambda (s) (memq (subscription-status s) '(() shared))))))
         (and subs
              (begin (for-each (lambda (s) (hold! s 'shared)) subs)
                     (new-reservation! task '() topics))))))))

(define (new-reservation! task exclusive shared)
  (let ((r (make-reservation task exclusive shared
                             (+ (monotonic-seconds) (lease)) 'reserved)))
    (subscriber-reservations-set! (the-subscriber)
                                  (cons r (subscriber-reservations (the-subscriber))))
    r))

(define (in-use-subject topic)
  (string->symbol (string-append (symbol->string topic) ".in_use")))

;; Frees a reservation's subjects, once.
(define (release! r)
  (if (with-subscriptions
        (lambda ()
          (and (not (eq? (reservation-state r) 'done))
               (begin
                 (reservation-state-set! r 'done)
                 (drop-reservation! r)
                 (for-each (lambda (topic) (let-go! topic #t))
                           (reservation-exclusive r))
                 (for-each (lambda (topic) (let-go! topic #f))
                           (reservation-shared r))
                 (pair? (reservation-exclusive r))))))
      ((subscriber-on-free (the-subscriber)))))

;; Under the lock.
(define (drop-reservation! r)
  (subscriber-reservations-set!
   (the-subscriber) (remove (lambda (x) (eq? x r)) (subscriber-reservations (the-subscriber)))))

;;> For \var{seconds}, reserves exclusive subjects here for \var{uid}'s requests; #f ends that.
(define (offer-subjects! uid . seconds)
  (with-subscriptions
    (lambda ()
      (subscriber-offered-set! (the-subscriber)
                               (and uid (cons uid (+ (monotonic-seconds) (car seconds))))))))

;; Caller holds the lock.
(define (offered-elsewhere? uid)
  (let ((offered (subscriber-offered (the-subscriber))))
    (and offered (not (eq? (car offered) uid))
         (< (monotonic-seconds) (cdr offered)))))

(define (let-go! topic exclusive?)
  (let ((s (find-subscription topic)))
    (when s
      (subscription-holds-set! s (max 0 (- (subscription-holds s) 1)))
      (when (zero? (subscription-holds s))
        (subscription-status-set! s '())
        (if exclusive? (remove-subscription! (in-use-subject topic)))))))

;; Marks r as being promised away; #f if its lease already ran out.
(define (claim! r)
  (with-subscriptions
    (lambda ()
      (and (eq? (reservation-state r) 'reserved)
           (begin (reservation-state-set! r 'running)
                  (drop-reservation! r)
                  #t)))))

(define (promise-for r proc args)
  (if (not r)
      (not-evaluated)
      (list #t (local-aspace-uid)
            (letrec ((promise
                      (encap
                       (lambda (commit?)
                         (cond
                          ((eq? commit? 'keep) (renew! r))
                          ((not (claim! r))
                           (error "this promise's reservation has ended"
                                  (reservation-task r)))
                          (else
                           (release-proxy! promise)
                           (dynamic-wind
                            (lambda () #f)
                            (lambda () (and commit? (apply proc args)))
                            (lambda () (release! r)))))))))
              promise))))

;; A promise applied to keep holds its subjects another lease, for a task
;; waiting for the rest (task/holding.scm); answers whether it still does.
(define (renew! r)
  (with-subscriptions
    (lambda ()
      (and (eq? (reservation-state r) 'reserved)
           (begin (reservation-deadline-set! r (+ (monotonic-seconds) (lease)))
                  #t)))))

;; Frees reservations whose promise was never applied: nothing is held for ever.
(define (lease-keeper)
  (thread-sleep! (min 1 (/ (lease) 4)))
  (for-each (lambda (r)
              (log-warn "lease ran out: freeing " (reservation-exclusive r)
                        (reservation-shared r) " held for "
                        (reservation-task r))
              (release! r))
            (with-subscriptions
              (lambda ()
                (filter (lambda (r)
                          (< (reservation-deadline r) (monotonic-seconds)))
                        (subscriber-reservations (the-subscriber))))))
  (lease-keeper))
