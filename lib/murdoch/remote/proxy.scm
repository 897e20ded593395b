;;;; Proxies (the thesis's encap): a procedure that runs where it was made.
;;
;; A proxy travels as its maker's uid and an id (sendable.scm); applied
;; elsewhere, it is a remote-apply back to its maker.

;; Global: a proxy made in any thread is applied from any connection.
(define *proxies* (make-hash-table eqv?))        ; id -> procedure
(define *proxy-stubs* (make-hash-table equal?))  ; (uid . id) -> proxy
(define *proxies-lock* (make-mutex 'proxies))
(define *next-proxy-id* 0)

;;> Returns a proxy for \var{proc}: a procedure that, applied in any address
;;> space, applies \var{proc} in this one and returns its result.
(define (encap proc)
  (with-lock *proxies-lock*
    (lambda ()
      (set! *next-proxy-id* (+ *next-proxy-id* 1))
      (hash-table-set! *proxies* *next-proxy-id* proc)
      (proxy-stub (local-aspace-uid) *next-proxy-id*))))

;;> Forgets \var{proxy} here: where it was made, the procedure behind it,
;;> so that applying it afterwards raises an error; elsewhere, only this
;;> address space's copy of it, which a later message may bring back.
(define (release-proxy! proxy)
  (let ((ref (proxy-procedure-ref proxy)))
    (with-lock *proxies-lock*
      (lambda ()
        (if (eq? (proxy-ref-uid ref) (local-aspace-uid))
            (hash-table-delete! *proxies* (proxy-ref-id ref)))
        (hash-table-delete! *proxy-stubs*
                            (cons (proxy-ref-uid ref) (proxy-ref-id ref)))))))

;; The one proxy procedure this address space has for (uid . id), so that
;; a proxy sent back and forth stays the same proxy.  Caller holds the lock.
(define (proxy-stub uid id)
  (let ((key (cons uid id)))
    (or (hash-table-ref/default *proxy-stubs* key #f)
        (let ((stub (make-proxy-procedure (make-proxy-ref uid id) apply-proxy)))
          (hash-table-set! *proxy-stubs* key stub)
          stub))))

(define (decode-proxy uid id)
  (with-lock *proxies-lock* (lambda () (proxy-stub uid id))))

(define (apply-proxy ref args)
  (let ((uid (proxy-ref-uid ref)))
    (if (eq? uid (local-aspace-uid))
        (let ((proc (with-lock *proxies-lock*
                      (lambda ()
                        (hash-table-ref/default *proxies* (proxy-ref-id ref)
                                                #f)))))
          (if (not proc)
              (error "this proxy no longer exists" uid (proxy-ref-id ref)))
          (apply proc args))
        (apply remote-apply (uid->aspace uid)
               (decode-proxy uid (proxy-ref-id ref)) args))))
