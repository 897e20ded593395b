;;; A test program that fails on purpose, for lab-test: a lab removed after
;;; a failure shows the last lines of its logs first.
(import (scheme base) (scheme file) (chibi test) (murdoch testing harness))

(define lab (make-test-lab '((aspace a))))
(call-with-output-file (string-append (test-lab-directory lab) "/a.log")
  (lambda (out) (write-string "the first line\nthe last line\n" out)))
(test "a test that fails" 1 2)
(remove-test-lab! lab)
