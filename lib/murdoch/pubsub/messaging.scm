;;;; Publish/subscribe messaging (thesis §4.1, appendix A.8 publish.scm).
;;
;; Each address space keeps its own subscription list: the subjects it
;; answers to, each free or reserved.  A message is addressed to a subject
;; or a list of them and carries a procedure; it is sent to every live
;; address space (the thesis's simulated broadcast), and an address space
;; evaluates it only when every subject of the address is one of its
;; subscriptions.
;;
;; Subjects are symbols; a dot makes levels (mobile.in_use).  In an
;; address, * stands for one level and > for all the levels that follow,
;; so mobile.* reaches mobile.in_use.  An exclusively reserved subject S is
;; joined by S.in_use while it is held, so that a sender can see why S is
;; not available, and request-status says who holds what.

;;; The subscription list

(define-record-type subscription
  (make-subscription topic status holds)
  subscription?
  (topic subscription-topic)
  (status subscription-status subscription-status-set!) ; (), task, shared
  (holds subscription-holds subscription-holds-set!))   ; live reservations

;; The thesis's names (A.8), global as there.  Guarded by
;; *subscriptions-lock*, as in the thesis: monitor threads change the
;; list while messages read it.  The list itself is never
;; changed, only replaced (add-subscription!, remove-subscription!), so
;; that addressed-here?, on every message, can read it without the lock.
(define *subscriptions* '())
(define *subscriptions-lock* (make-mutex 'subscriptions))

(define (with-subscriptions thunk) (with-lock *subscriptions-lock* thunk))

(define (find-subscription topic) (subscription-in *subscriptions* topic))

;; A loop of its own, not find (docs/speed.md, What Chibi charges).
(define (subscription-in subscriptions topic)
  (cond ((null? subscriptions) #f)
        ((eq? (subscription-topic (car subscriptions)) topic) (car subscriptions))
        (else (subscription-in (cdr subscriptions) topic))))

(define (add-subscription! topic)
  (if (not (find-subscription topic))
      (set! *subscriptions*
            (cons (make-subscription topic '() 0) *subscriptions*))))

(define (remove-subscription! topic)
  (set! *subscriptions*
        (remove (lambda (s) (eq? (subscription-topic s) topic))
                *subscriptions*)))

;;> Starts listening to \var{topic}; does nothing if already listening.
(define (subscribe topic)
  (check-subjects "subscribe" (list topic))
  (with-subscriptions (lambda () (add-subscription! topic)))
  #t)

;;> Stops listening to \var{topic}; does nothing if not listening.
(define (unsubscribe topic)
  (check-subjects "unsubscribe" (list topic))
  (with-subscriptions (lambda () (remove-subscription! topic)))
  #t)

;;> The subjects this address space listens to.
(define (subscriptions)
  (with-subscriptions (lambda () (map subscription-topic *subscriptions*))))

;;> The status of \var{topic}: () when free, the task-name that holds it
;;> exclusively, \scheme{shared} while non-exclusive readers hold it, or
;;> #f when not subscribed.
(define (topic-status topic)
  (with-subscriptions
    (lambda ()
      (let ((s (find-subscription topic)))
        (and s (subscription-status s))))))

;;> Sets the status of \var{topic}, when subscribed.
(define (set-topic-status! topic status)
  (with-subscriptions
    (lambda ()
      (let ((s (find-subscription topic)))
        (if s (subscription-status-set! s status))))))

;;> Subscribes address space \var{uid} to \var{topic}, a subject or a list.
(define (subscribe-remote uid topic)
  (remote-apply (uid->aspace uid) for-each subscribe (subject-list topic)))

;;> Unsubscribes address space \var{uid} from \var{topic}.
(define (unsubscribe-remote uid topic)
  (remote-apply (uid->aspace uid) for-each unsubscribe (subject-list topic)))

;;; Addresses

(define (subject-list topic) (if (list? topic) topic (list topic)))

;; Wrong arguments are refused where the call is made, naming the call,
;; rather than answered by every receiver with an error of its own.
(define (check-subjects who subjects)
  (for-each (lambda (s)
              (if (not (symbol? s))
                  (error (string-append who ": a subject is a symbol") s)))
            subjects))

(define (check-subjects-and-procedure who subjects proc)
  (check-subjects who subjects)
  (if (not (procedure? proc))
      (error (string-append who ": not a procedure") proc)))

(define (subject-levels subject)
  (let ((s (symbol->string subject)))
    (let loop ((start 0) (i 0) (acc '()))
      (cond ((= i (string-length s))
             (reverse (cons (substring s start i) acc)))
            ((char=? (string-ref s i) #\.)
             (loop (+ i 1) (+ i 1) (cons (substring s start i) acc)))
            (else (loop start (+ i 1) acc))))))

;; A predicate true of the topics the address subject pattern reaches,
;; made once per message (docs/speed.md).
(define (subject-matcher pattern)
  (let ((levels (subject-levels pattern)))
    (if (or (member "*" levels) (member ">" levels))
        (lambda (topic) (levels-match? levels (subject-levels topic)))
        (lambda (topic) (eq? pattern topic)))))

(define (levels-match? p t)
  (cond ((null? p) (null? t))
        ((string=? (car p) ">") (pair? t))
        ((null? t) #f)
        ((or (string=? (car p) "*") (string=? (car p) (car t)))
         (levels-match? (cdr p) (cdr t)))
        (else #f)))

;;> True when every subject of the address is among the subscriptions
;;> (the thesis says "proper subset"; it means subset).  It takes no lock:
;;> it reads the list once, and then only the topics, which never change.
;;> A subject subscribed as it is matches itself, wildcards included: the
;;> common case (all, a uid), which needs no matcher (docs/speed.md).
(define (addressed-here? topic)
  (if (list? topic)
      (subjects-here? *subscriptions* topic)
      (subject-here? *subscriptions* topic)))

(define (subjects-here? subscriptions subjects)
  (or (null? subjects)
      (and (subject-here? subscriptions (car subjects))
           (subjects-here? subscriptions (cdr subjects)))))

(define (subject-here? subscriptions pattern)
  (or (subscription-in subscriptions pattern)
      (let ((matches? (subject-matcher pattern)))
        (any (lambda (s) (matches? (subscription-topic s))) subscriptions))))

;;; Sending

;; Sends a message to the lab: a result (call.scm) of each address space
;; that it reached.  An address that is one address space's uid reaches
;; that address space alone (each subscribes to its own uid and to no
;; other's), so it is sent there only: metrics ask each candidate point to
;; point, and would otherwise cost N messages each.
(define (deliver kind topic proc . args)
  (cond ((and (symbol? topic) (live-aspace topic))
         => (lambda (a) (call-all (list a) kind proc args)))
        (else (apply (if (eq? kind 'run) broadcast-run! broadcast-apply) proc args))))

;;> Publishes a message (asynchronous, Figure 4.1): each live address
;;> space subscribed to every subject of \var{topic} applies \var{proc} to
;;> \var{args}.  Answers the uids of the address spaces that acknowledged,
;;> which says nothing of who evaluated it.
(define (publish topic proc . args)
  (check-subjects-and-procedure "publish" (subject-list topic) proc)
  (filter-map (lambda (r) (and (result-ok? r) (result-uid r)))
              (told-failures 'publish
                             (deliver 'run topic receive-publication topic
                                      (local-aspace-uid) proc args))))

;;> Publishes and waits for the results (synchronous, Figure 4.2): answers
;;> ((uid result) ...) for the address spaces that evaluated the message,
;;> possibly none.  One where the procedure raises is left out, and one
;;> that dies or stalls after (remote-timeout) seconds; the log tells of
;;> each.
(define (request topic proc . args)
  (check-subjects-and-procedure "request" (subject-list topic) proc)
  (answers 'request (deliver 'apply topic receive-request topic
                             (local-aspace-uid) proc args)))

;; The evaluators' (uid value) from results whose values are receivers'
;; answers (see receive-request); the failures are told (see
;; told-failures).
(define (answers what results)
  (filter-map (lambda (r)
                (and (result-ok? r) (evaluated? (result-value r))
                     (evaluation (result-value r))))
              (told-failures what results)))

;; A receiver whose evaluation raised, or that did not answer, is left out
;; of what publish and request answer; the log says which and why, so that
;; a mistake in the procedure does not pass for a lab where nobody is
;; subscribed.  Answers results.
(define (told-failures what results)
  (for-each (lambda (r) (if (not (result-ok? r)) (tell-failure what r))) results)
  results)

(define (tell-failure what r)
  (log-warn what " on " (result-uid r) " failed: " (result-value r)))

;; A capability list in the ((exclusive ...) (non-exclusive ...)) layout,
;; from any of the appendix's forms: a bare subject or a flat list of
;; subjects, needed non-exclusively, or the two lists.
(define (capability-layout topic)
  (cond ((not (list? topic)) (list '() (list topic)))
        ((null? topic) (list '() '()))
        ((not (list? (car topic))) (list '() topic))
        (else (list (car topic) (if (pair? (cdr topic)) (cadr topic) '())))))

;;> Reserves, then promises (Figure 4.3): each live address space that has
;;> every subject of \var{topic}, with the exclusive ones free (or held for
;;> \var{task-name}), reserves the exclusive ones for \var{task-name} and
;;> answers a promise.  Answers ((uid promise) ...).  A promise applied to
;;> #t applies \var{proc} to \var{args} there, frees the subjects and
;;> returns the result; applied to #f it only frees them; applied to
;;> \scheme{keep}, it holds them for another lease.  A promise never
;;> applied is freed after the lab's lease.
(define (request-exclusive topic task-name proc . args)
  (let ((layout (capability-layout topic)))
    (check-subjects-and-procedure "request-exclusive" (apply append layout) proc)
    (answers 'request-exclusive
             (broadcast-apply receive-request-exclusive layout task-name
                              (local-aspace-uid) proc args))))

;;> As request-exclusive, but the subjects of \var{topic} are reserved for
;;> sharing: other non-exclusive requests still get them, exclusive ones
;;> are refused until every promise is applied (the thesis's chapter 6).
(define (request-non-exclusive topic task-name proc . args)
  (let ((subjects (subject-list topic)))
    (check-subjects-and-procedure "request-non-exclusive" subjects proc)
    (answers 'request-non-exclusive
             (broadcast-apply receive-request-non-exclusive subjects task-name
                              (local-aspace-uid) proc args))))

;;> One message to the whole lab for every component of a negotiation
;;> (pose-task's round), where the thesis sends each its own
;;> request-exclusive or request, each to the whole lab: a lab of N then
;;> reads N messages a round, not N for each component, and answers the
;;> metrics' askings in the same message, not in a round of their own.
;;> Each of \var{components} is (type layout proc askings): type
;;> exclusive or non-exclusive, layout as capability-layout gives it, the
;;> procedure a promise applies (request's, for a non-exclusive one), and
;;> the procedures that each candidate is asked for its measures.
;;> Answers, per component in order, (response asked): response as
;;> request-exclusive, or request to the layout's non-exclusive subjects,
;;> answers; asked, ((uid answer ...) ...), each candidate's answers to the
;;> askings, (#t value) or (#f message) each.
(define (request-components task-name components)
  (let* ((n (length components))
         (rows (checked-rows (broadcast-apply receive-components components task-name
                                              (local-aspace-uid))
                             n)))
    (map (lambda (c i)
           (list (column-answers (if (eq? (car c) 'exclusive) 'request-exclusive 'request)
                                 rows i)
                 (column-asked rows i)))
         components (iota n))))

;; rows, each receiver's result, with the value of one that is not n
;; entries (answer asked) made a failure: each row is checked once, and
;; each component's column read from it after (docs/speed.md).
(define (checked-rows rows n)
  (cond ((null? rows) '())
        ((or (not (result-ok? (car rows))) (row-of? (result-value (car rows)) n))
         (cons (car rows) (checked-rows (cdr rows) n)))
        (else (cons (make-result (result-uid (car rows)) #f
                                 "a malformed answer to request-components")
                    (checked-rows (cdr rows) n)))))

(define (row-of? value n)
  (and (list? value) (= (length value) n) (entries? value)))

(define (entries? value)
  (or (null? value)
      (and (list? (car value)) (= (length (car value)) 2) (pair? (caar value))
           (entries? (cdr value)))))

;; Component i's answers, as request-exclusive's or request's: what each
;; receiver that evaluated it answered; a failed row is logged as what's.
(define (column-answers what rows i)
  (cond ((null? rows) '())
        ((not (result-ok? (car rows)))
         (tell-failure what (car rows))
         (column-answers what (cdr rows) i))
        ((evaluated? (row-answer (car rows) i))
         (cons (evaluation (row-answer (car rows) i)) (column-answers what (cdr rows) i)))
        (else (column-answers what (cdr rows) i))))

;; Component i's askings' answers, (uid answer ...) for each receiver
;; that evaluated it.
(define (column-asked rows i)
  (cond ((null? rows) '())
        ((and (result-ok? (car rows)) (evaluated? (row-answer (car rows) i)))
         (cons (cons (result-uid (car rows))
                     (component-asked (list-ref (result-value (car rows)) i)))
               (column-asked (cdr rows) i)))
        (else (column-asked (cdr rows) i))))

(define (row-answer row i) (component-answer (list-ref (result-value row) i)))

;;> Who holds what: for each address space with a subscription matching
;;> \var{topic}, (uid ((subject status) ...)).
(define (request-status topic)
  (filter (lambda (r) (pair? (cadr r)))
          (map (lambda (r) (list (car r) (cadr r)))
               (request 'all subscription-statuses topic))))

;;> The (subject status) of the subscriptions here that match \var{topic}.
(define (subscription-statuses topic)
  (let ((matches? (subject-matcher topic)))
    (with-subscriptions
      (lambda ()
        (filter-map (lambda (s)
                      (and (matches? (subscription-topic s))
                           (list (subscription-topic s)
                                 (subscription-status s))))
                    *subscriptions*)))))
