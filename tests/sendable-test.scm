;;; Murdoch's lambda and the encoding of values, in one process.
(import (except (scheme base) lambda define) (scheme eval) (scheme read)
        (scheme write) (scheme cxr) (scheme file) (srfi 1) (chibi test)
        (only (meta) mutable-environment)
        (rename (murdoch code sendable) (sendable-lambda lambda)
                (sendable-define define))
        (murdoch lab) (murdoch testing harness))

;; The limits of a lab of clauses (max-depth, max-frame), read from a
;; file of its own, this process's node.
(define (take-limits! clauses)
  (let ((lab (make-test-lab clauses)))
    (open-node! (read-lab (test-lab-file lab)))
    (remove-test-lab! lab)
    (set-value-limits!)))

(take-limits! '())

(define env (environment '(scheme base)))
(define (round-trip x)
  (let ((text (let ((out (open-output-string)))
                (write (encode x env "the value") out)
                (get-output-string out))))
    ((make-decoder env (lambda (uid id) (list 'proxy uid id)))
     (read (open-input-string text)))))

;; This process's resident memory in kB (Linux's /proc/self/status).
(define (resident-kb)
  (call-with-input-file "/proc/self/status"
    (lambda (in)
      (let loop ()
        (let ((line (read-line in)))
          (if (string=? (substring line 0 6) "VmRSS:")
              (read (open-input-string (substring line 6 (string-length line))))
              (loop)))))))

(define (show n) (list later n))        ; later is defined below
(define later 'defined-later)
(define (maker coords) (lambda () coords))
(define (shadow info) (lambda () info)) ; the macro's own variable is hidden

(test-begin "sendable")
;; Kept by closure, a request's thunk made afresh 100,000 times took the
;; heap from 38 to 103 MB: the table's bucket vector, regrown, found no
;; room among the closures kept.  First, while nothing else is kept.
(test "a closure made afresh each time is kept once: the heap stays" #t
  (let ((before (resident-kb)))
    (do ((i 0 (+ i 1))) ((= i 100000))
      (encode (lambda () #t) env "it")
      (make-vector 30 i))
    (< (- (resident-kb) before) 20000)))
(test "a global defined after the lambda that uses it" '(defined-later 1)
  (show 1))
(test "a closure carries its source and captured locals"
    '#(murdoch:closure (lambda () coords) ((coords 1 2)))
  (encode (maker '(1 2)) env "it"))
(test "and runs where it lands" '(1 2) ((round-trip (maker '(1 2)))))
(test "a user's variable named info is the user's" 'mine ((shadow 'mine)))
(test "rest arguments" '(1 (2 3)) ((lambda (a . rest) (list a rest)) 1 2 3))
(test "a procedure of the environment travels by name"
    '#(murdoch:global car)
  (encode car env "it"))
(test "data of every kind" '(1 2.5 "s" #\c sym #u8(1) #(1 #(2)) ())
  (round-trip '(1 2.5 "s" #\c sym #u8(1) #(1 #(2)) ())))
(test "a user's vector that looks like a tag stays a vector"
    '#(murdoch:global car)
  (round-trip (vector 'murdoch:global 'car)))
(test "a port is refused, naming the variable"
    "cannot send variable port of (lambda () port): it is an output port"
  (guard (e ((send-error? e) (error-object-message e)))
    (let ((port (current-output-port)))
      (encode (lambda () port) env "it"))))
(define (send-error-of thunk)
  (guard (e ((send-error? e) (error-object-message e))) (thunk) 'sent))
(define (nested n) (if (= n 0) '() (list (nested (- n 1)))))
(test-group "the limits, through the look that passes plain data as it is"
  (take-limits! '((max-depth 50) (max-frame 2000)))
  (test "plain data nested to the limit goes as it is" (nested 49)
    (encode (nested 49) env "it"))
  (test "deeper is refused" "it nests deeper than the lab's max-depth, 50"
    (send-error-of (lambda () (encode (nested 51) env "it"))))
  (test "a circular list is refused"
      "cannot send it: it is larger than a frame holds, or circular"
    (send-error-of (lambda () (let ((c (list 1 2))) (set-cdr! (cdr c) c)
                                (encode c env "it")))))
  (test "so is a value, not plain, with more pairs than the limit"
      "cannot send it: it is larger than a frame holds, or circular"
    (send-error-of (lambda () (encode (cons car (iota 1000)) env "it"))))
  (test "a list of plain data beside a closure round-trips"
      '(1 (2 "three") four)
    (let ((p (round-trip (list '(1 (2 "three")) (lambda () 'four)))))
      (list (caar p) (cadr (car p)) ((cadr p)))))
  (take-limits! '()))
(test "a receiver's table of compiled sources, emptied when full, compiles again"
    '(0 4100 0)
  ;; 4,101 sources, more than the table holds, through one decoder.
  (let ((decode (make-decoder env (lambda (uid id) #f)))
        (code (lambda (n) (vector 'murdoch:closure `(lambda () ,n) '()))))
    (let ((first ((decode (code 0)))))
      (do ((n 1 (+ n 1))) ((= n 4100)) (decode (code n)))
      (list first ((decode (code 4100))) ((decode (code 0)))))))
(test "a closure that captures nothing comes as one procedure; one that captures comes anew"
    '(#t 5 #f (1 2))
  (let ((decode (make-decoder env (lambda (uid id) #f)))
        (free (lambda () (vector 'murdoch:closure '(lambda (x) (+ x 1)) '())))
        (bound (lambda (n) (vector 'murdoch:closure '(lambda () n) (list (cons 'n n))))))
    (let ((a (decode (free))) (b (decode (free)))
          (c (decode (bound 1))) (d (decode (bound 2))))
      (list (eq? a b) (b 4) (eq? c d) (list (c) (d))))))
(test-group "the encodings kept by procedure"
  (let ((genv (mutable-environment '(scheme base))))
    (eval '(define (twice x) (* 2 x)) genv)
    (let ((old (eval 'twice genv)))
      (test "a global goes by its name, again and again"
          '(#(murdoch:global twice) #(murdoch:global twice))
        (list (encode old genv "it") (encode old genv "it")))
      (eval '(define (twice x) (+ x x)) genv)
      (test "and no more once the name is bound to another procedure"
          "cannot send it: it is a procedure made without Murdoch's lambda"
        (send-error-of (lambda () (encode old genv "it"))))
      (test "the name goes with the procedure now bound to it"
          '#(murdoch:global twice)
        (encode (eval 'twice genv) genv "it"))
      (test "in another environment, the encoding is that environment's"
          "cannot send it: it is a procedure made without Murdoch's lambda"
        (send-error-of (lambda () (encode (eval 'twice genv) env "it"))))))
  (let ((constant (lambda () 'seven)))
    (test "a closure that captures nothing goes as its source, again"
        '(#(murdoch:closure (lambda () 'seven) ())
          #(murdoch:closure (lambda () 'seven) ()))
      (list (encode constant env "it") (encode constant env "it")))))
(test-end)
(test-exit)
