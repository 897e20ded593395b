;;;; Proxies (the thesis's encap): a procedure that runs where it was made,
;;;; travelling as its maker's uid and an id.

(define-record-type proxies
  (make-proxies made stubs lock next-id)
  proxies?
  (made proxies-made)                   ; id -> procedure
  (stubs proxies-stubs)                 ; (uid . id) -> proxy
  (lock proxies-lock)
  (next-id proxies-next-id proxies-next-id-set!))

;; Global: a proxy made in any thread is applied from any connection.
(define *proxies* (make-proxies (make-hash-table eqv?) (make-hash-table equal?)
                                (make-mutex 'proxies) 0))

(define (with-proxies thunk) (with-lock (proxies-lock *proxies*) thunk))

;;> Returns a proxy for \var{proc}: a procedure that, applied in any address
;;> space, applies \var{proc} in this one and returns its result.
(define (encap proc)
  (with-proxies
    (lambda ()
      (let ((id (+ 1 (proxies-next-id *proxies*))))
        (proxies-next-id-set! *proxies* id)
        (hash-table-set! (proxies-made *proxies*) id proc)
        (proxy-stub (local-aspace-uid) id)))))

;;> Forgets \var{proxy} here: where it was made, applying it afterwards
;;> raises; elsewhere only this copy goes, which a later message may bring back.
(define (release-proxy! proxy)
  (let ((ref (proxy-procedure-ref proxy)))
    (with-proxies
      (lambda ()
        (if (eq? (proxy-ref-uid ref) (local-aspace-uid))
            (hash-table-delete! (proxies-made *proxies*) (proxy-ref-id ref)))
        (hash-table-delete! (proxies-stubs *proxies*)
                            (cons (proxy-ref-uid ref) (proxy-ref-id ref)))))))

;; The one proxy procedure for (uid . id), kept the same; caller holds the lock.
(define (proxy-stub uid id)
  (let ((key (cons uid id)))
    (or (hash-table-ref/default (proxies-stubs *proxies*) key #f)
        (let ((stub (make-proxy-procedure (make-proxy-ref uid id) apply-proxy)))
          (hash-table-set! (proxies-stubs *proxies*) key stub)
          stub))))

(define (decode-proxy uid id)
  (with-proxies (lambda () (proxy-stub uid id))))

(define (apply-proxy ref args)
  (let ((uid (proxy-ref-uid ref)))
    (if (eq? uid (local-aspace-uid))
        (let ((proc (with-proxies
                      (lambda ()
                        (hash-table-ref/default (proxies-made *proxies*)
                                                (proxy-ref-id ref) #f)))))
          (if (not proc)
              (error "this proxy no longer exists" uid (proxy-ref-id ref)))
          (apply proc args))
        (apply remote-apply (uid->aspace uid)
               (decode-proxy uid (proxy-ref-id ref)) args))))
