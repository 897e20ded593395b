;;;; Address spaces: identity, peers and live membership (thesis §3.3.2).
;;
;; An address space is one Chibi process with a uid; the lab file says
;; where each listens.  This process joins its lab as one of them
;; (join-lab!), once, and learns the others from the lab and from their
;; hellos and beacons.

;;; Address spaces

(define-record-type aspace
  (make-aspace uid host port)
  ;;> True for an address space, as uid->aspace and local-aspace answer.
  aspace?
  ;;> The uid of an address space, a symbol.
  (uid aspace-uid)
  (host aspace-host)
  (port aspace-port))

(define *local* #f)                     ; the local aspace, once started
(define *started-at* #f)                ; (utc-seconds) then
(define *lab* #f)
(define *peers* (make-hash-table eq?))  ; uid -> aspace, from lab and hellos
(define *peers-lock* (make-mutex 'peers))

;;> The local address space.
(define (local-aspace)
  (or *local* (error "this process has not joined a lab")))

;;> Makes \var{port} the local address space's: the free one the kernel
;;> chose for a guest, which listens on port 0 and says where in its hellos.
(define (local-aspace-port-set! port)
  (set! *local* (make-aspace (aspace-uid *local*) (aspace-host *local*) port))
  (learn-aspace! *local*))

;;> The (utc-seconds) at which this address space joined its lab.
(define (aspace-started-at) *started-at*)

;;> The uid of the local address space.
(define (local-aspace-uid) (aspace-uid (local-aspace)))

;;> The address space named \var{uid}.
(define (uid->aspace uid)
  (or (with-lock *peers-lock* (lambda () (hash-table-ref/default *peers* uid #f)))
      (error "no address space of this uid is known" uid)))

;;> The uids of every address space known here (the thesis's *uids*).
(define (known-uids)
  (with-lock *peers-lock* (lambda () (hash-table-keys *peers*))))

(define (learn-aspace! a)
  (with-lock *peers-lock*
    (lambda () (hash-table-set! *peers* (aspace-uid a) a))))

;;; Live membership
;;
;; Address spaces come and go.  One that fails to connect, loses its
;; connection or does not answer in time is taken out of the live set, so
;; that publish and request stop waiting on it; a prober tries it again
;; every second and puts it back when it answers.  A newcomer is learned
;; from its hello, so it joins by calling anyone.

(define *unreachable* (make-hash-table eq?))   ; uid -> #t

(define (note-unreachable! uid)
  (if (not (eq? uid (aspace-uid *local*)))
      (with-lock *peers-lock*
        (lambda () (hash-table-set! *unreachable* uid #t)))))

;; uid answers again, or a beacon of it came.
(define (note-reachable! uid)
  (with-lock *peers-lock* (lambda () (hash-table-delete! *unreachable* uid))))

;; The uids taken out of the live set, for the prober to try again.
(define (unreachable-uids)
  (with-lock *peers-lock* (lambda () (hash-table-keys *unreachable*))))

;;> The uids of the address spaces that answer: the broadcast set.
(define (live-uids)
  (with-lock *peers-lock*
    (lambda ()
      (remove (lambda (uid) (hash-table-ref/default *unreachable* uid #f))
              (hash-table-keys *peers*)))))

;;; Settings

(define *default-timeout* 5)

;;> Seconds remote-apply waits for an answer: the global default.
(define (set-remote-timeout! seconds) (set! *default-timeout* seconds))

;;> A per-call override: (parameterize ((remote-timeout 1)) ...).
(define remote-timeout (make-parameter #f))
(sandbox-parameter! remote-timeout)

(define (current-timeout) (or (remote-timeout) *default-timeout*))

;;; The environment received code runs in

(define *environment* #f)
(define *decode* #f)

;;> The environment received code runs in: R7RS base, Murdoch's API and the
;;> lab's code files; no file, process, load or eval primitives.
(define (lab-environment) *environment*)

;; The value that received code, an encoded value, stands for here.  The
;; code is rebuilt in place (make-decoder): it must be the reader's, fresh
;; from a frame, and is not used again.
(define (decode-value code) (*decode* code))

(define (describe-procedure proc)
  (let ((encoded (guard (e (#t #f)) (encode proc *environment* "procedure"))))
    (cond ((and (vector? encoded) (eq? (vector-ref encoded 0) 'murdoch:global))
           (vector-ref encoded 1))
          ((and (vector? encoded) (eq? (vector-ref encoded 0) 'murdoch:closure))
           (vector-ref encoded 1))
          (else proc))))

;;> The lab this address space belongs to.
(define (current-lab) (or *lab* (error "this process has not joined a lab")))

;;> Makes this process the address space \var{uid} of \var{lab}, listening
;;> on \var{port}, receiving code into \var{environment} and decoding what
;;> it receives with \var{decode}; answers the local aspace.
(define (join-lab! lab uid host port environment decode)
  (set! *lab* lab)
  (set! *started-at* (utc-seconds))
  (set! *local* (make-aspace uid host port))
  (set! *environment* environment)
  (set! *decode* decode)
  (set! *default-timeout* (lab-setting lab 'timeout))
  (for-each (lambda (a)
              (learn-aspace! (make-aspace (lab-aspace-uid a) (lab-aspace-host a)
                                          (lab-aspace-port a))))
            (lab-aspaces lab))
  (learn-aspace! *local*)
  *local*)
