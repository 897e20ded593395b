;;;; Publish/subscribe messaging (thesis §4.1, appendix A.8 publish.scm).
;;;; Each address space keeps its subscription list; a message, addressed
;;;; to subjects, goes to every live address space, which evaluates it only
;;;; when it subscribes to all of them.  A dot makes levels (mobile.in_use);
;;;; in an address * is one level and > the rest.  A reserved subject S is
;;;; joined by S.in_use while held, so a sender can see why S is taken.

;;; The subscription list

(define-record-type subscription
  (make-subscription topic status holds)
  subscription?
  (topic subscription-topic)
  (status subscription-status subscription-status-set!) ; (), task, shared
  (holds subscription-holds subscription-holds-set!))   ; live reservations

;; The node's subscriber part: this address space's subscription list
;; (the thesis's *subscriptions*, A.8), its reservations not yet promised
;; away (receiving.scm), the poser a freed robot is offered to, and the
;; task layer's hook run when exclusive subjects are freed.  All under the
;; lock; the list is replaced, never changed, so addressed-here? needs none.
(define-record-type subscriber
  (make-subscriber list lock reservations offered on-free)
  subscriber?
  (list subscriber-list subscriber-list-set!)
  (lock subscriber-lock)
  (reservations subscriber-reservations subscriber-reservations-set!)
  (offered subscriber-offered subscriber-offered-set!) ; (uid . until), or #f
  (on-free subscriber-on-free))

(define-syntax the-subscriber (syntax-rules () ((_) (node-subscriber *node*))))

;;> Makes this node a subscriber, listening to nothing yet: \var{on-free}
;;> is run, outside any lock, whenever exclusive subjects here are freed.
(define (open-subscriber! on-free)
  (node-subscriber-set! (this-node)
                        (make-subscriber '() (make-mutex 'subscriptions) '() #f on-free)))

(define (with-subscriptions thunk) (with-lock (subscriber-lock (the-subscriber)) thunk))

(define (find-subscription topic) (subscription-in (subscriber-list (the-subscriber)) topic))

;; A loop of its own, not find (docs/speed.md).
(define (subscription-in subscriptions topic)
  (cond ((null? subscriptions) #f)
        ((eq? (subscription-topic (car subscriptions)) topic) (car subscriptions))
        (else (subscription-in (cdr subscriptions) topic))))

(define (add-subscription! topic)
  (if (not (find-subscription topic))
      (subscriber-list-set! (the-subscriber)
                            (cons (make-subscription topic '() 0)
                                  (subscriber-list (the-subscriber))))))

(define (remove-subscription! topic)
  (subscriber-list-set! (the-subscriber)
                        (remove (lambda (s) (eq? (subscription-topic s) topic))
                                (subscriber-list (the-subscriber)))))

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
  (with-subscriptions
    (lambda () (map subscription-topic (subscriber-list (the-subscriber))))))

;;> The status of \var{topic}: () when free, the task-name that holds it
;;> exclusively, \scheme{shared}, or #f when not subscribed.
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

;; Wrong arguments are refused here, naming the call, not by every receiver.
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

;; A predicate of the topics pattern reaches, made once a message.
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

;;> Whether every subject of the address is subscribed (the thesis's
;;> "proper subset" means subset), without the lock; an exact subject needs
;;> no matcher, the common case (docs/speed.md).
(define (addressed-here? topic)
  (if (list? topic)
      (subjects-here? (subscriber-list (the-subscriber)) topic)
      (subject-here? (subscriber-list (the-subscriber)) topic)))

(define (subjects-here? subscriptions subjects)
  (or (null? subjects)
      (and (subject-here? subscriptions (car subjects))
           (subjects-here? subscriptions (cdr subjects)))))

;; No or, whose let makes a closure (docs/speed.md).
(define (subject-here? subscriptions pattern)
  (if (subscription-in subscriptions pattern)
      #t
      (subject-matched? subscriptions (subject-matcher pattern))))

(define (subject-matched? subscriptions matches?)
  (any (lambda (s) (matches? (subscription-topic s))) subscriptions))

;;; Sending

(define-syntax evaluated? (syntax-rules () ((_ answer) (car answer)))) ; (#t UID VALUE)
(define-syntax evaluation (syntax-rules () ((_ answer) (cdr answer)))) ; (UID VALUE)
(define-syntax component-answer (syntax-rules () ((_ entry) (car entry)))) ; (ANSWER ASKED)
(define-syntax component-asked (syntax-rules () ((_ entry) (cadr entry)))) ; macros: docs/speed.md

;; Sends a message to the lab: a result for each address space reached; a
;; uid goes to that address space alone, as metrics ask point to point.
(define (deliver kind topic proc . args)
  (cond ((and (symbol? topic) (live-aspace topic))
         => (lambda (a) (call-all (list a) kind proc args)))
        (else (apply (if (eq? kind 'run) broadcast-run! broadcast-apply) proc args))))

;;> Publishes a message (asynchronous, Figure 4.1): each live address
;;> space subscribed to every subject of \var{topic} applies \var{proc} to
;;> \var{args}.  Answers the uids that acknowledged.
(define (publish topic proc . args)
  (check-subjects-and-procedure "publish" (subject-list topic) proc)
  (filter-map (lambda (r) (and (result-ok? r) (result-uid r)))
              (told-failures 'publish
                             (deliver 'run topic receive-publication topic
                                      (local-aspace-uid) proc args))))

;;> Publishes and waits for the results (synchronous, Figure 4.2): answers
;;> ((uid result) ...) for the address spaces that evaluated the message;
;;> one that raised, died or stalled is left out, and logged.
(define (request topic proc . args)
  (check-subjects-and-procedure "request" (subject-list topic) proc)
  (answers 'request (deliver 'apply topic receive-request topic
                             (local-aspace-uid) proc args)))

;; The evaluators' (uid value) from results; failures are told.
(define (answers what results)
  (filter-map (lambda (r)
                (and (result-ok? r) (evaluated? (result-value r))
                     (evaluation (result-value r))))
              (told-failures what results)))

;; Logs each receiver that raised or did not answer: a mistake must not
;; pass for a lab where nobody subscribes.
(define (told-failures what results)
  (for-each (lambda (r) (if (not (result-ok? r)) (tell-failure what r))) results)
  results)

(define (tell-failure what r)
  (log-warn what " on " (result-uid r) " failed: " (result-value r)))

;; A capability list as ((exclusive ...) (non-exclusive ...)), from any appendix form.
(define (capability-layout topic)
  (cond ((not (list? topic)) (list '() (list topic)))
        ((null? topic) (list '() '()))
        ((not (list? (car topic))) (list '() topic))
        (else (list (car topic) (if (pair? (cdr topic)) (cadr topic) '())))))

;;> Reserves, then promises (Figure 4.3): each live address space that has
;;> every subject of \var{topic}, the exclusive ones free for
;;> \var{task-name}, reserves them and answers a promise: ((uid promise)
;;> ...).  A promise applied to #t applies \var{proc} to \var{args} there,
;;> frees the subjects and returns the result; to #f only frees them; to
;;> \scheme{keep} holds them another lease.  Unapplied, the lease frees them.
(define (request-exclusive topic task-name proc . args)
  (let ((layout (capability-layout topic)))
    (check-subjects-and-procedure "request-exclusive" (apply append layout) proc)
    (answers 'request-exclusive
             (broadcast-apply receive-request-exclusive layout task-name
                              (local-aspace-uid) proc args))))

;;> As request-exclusive, but the subjects are shared: other non-exclusive
;;> requests still get them, exclusive ones wait for every promise (ch. 6).
(define (request-non-exclusive topic task-name proc . args)
  (let ((subjects (subject-list topic)))
    (check-subjects-and-procedure "request-non-exclusive" subjects proc)
    (answers 'request-non-exclusive
             (broadcast-apply receive-request-non-exclusive subjects task-name
                              (local-aspace-uid) proc args))))

;;> One message to the whole lab for every component of a negotiation,
;;> with the metrics' askings, where the thesis sends one each.  Each of
;;> \var{components} is (type layout proc askings); answers (response
;;> asked) for each, response as request-exclusive or request gives,
;;> asked ((uid answer ...) ...), each answer (#t value) or (#f message).
(define (request-components task-name components)
  (let ((n (length components)))
    (component-columns components n
                       (audience-apply receive-components components task-name
                                       (local-aspace-uid)))))

;;> The uids that request-components asks, or #f, the thesis's whole
;;> lab.  Only an address space subscribed to a component's subjects
;;> answers it, and a task that waits knows, from its poser's look, which
;;> are: asked alone, a start of a waiting task costs messages to its
;;> robots, not to every address space of the lab (docs/allocation.md).
(define request-audience (make-parameter #f))

(define (audience-apply proc . args)
  (let ((uids (request-audience)))
    (if uids
        (call-all (filter-map live-aspace (delete-duplicates uids)) 'apply proc args)
        (apply broadcast-apply proc args))))

;; Every component's (response asked), in one pass; a row not of n entries fails.
(define (component-columns components n rows)
  (let ((answers (make-vector n '())) (asked (make-vector n '())))
    (for-each (lambda (row) (take-row! components n row answers asked)) rows)
    (map (lambda (i) (list (reverse (vector-ref answers i)) (reverse (vector-ref asked i))))
         (iota n))))

(define (take-row! components n row answers asked)
  (cond ((not (result-ok? row)) (tell-failures components row))
        ((row-of? (result-value row) n)
         (take-entries! (result-value row) (result-uid row) 0 answers asked))
        (else (tell-failures components
                             (make-result (result-uid row) #f
                                          "a malformed answer to request-components")))))

(define (tell-failures components row)
  (for-each (lambda (c)
              (tell-failure (if (eq? (car c) 'exclusive) 'request-exclusive 'request) row))
            components))

(define (row-of? value n) (and (list? value) (entries-of? value n)))

(define (entries-of? value n)           ; n entries (ANSWER ASKED), without length
  (if (null? value)
      (eq? n 0)
      (and (pair? (car value)) (pair? (caar value)) (pair? (cdar value))
           (null? (cddr (car value))) (entries-of? (cdr value) (- n 1)))))

(define (take-entries! entries uid i answers asked) ; each evaluated on its column
  (when (pair? entries)
    (when (evaluated? (component-answer (car entries)))
      (vector-set! answers i (cons (evaluation (component-answer (car entries)))
                                   (vector-ref answers i)))
      (vector-set! asked i (cons (cons uid (component-asked (car entries)))
                                 (vector-ref asked i))))
    (take-entries! (cdr entries) uid (+ i 1) answers asked)))

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
                    (subscriber-list (the-subscriber)))))))
