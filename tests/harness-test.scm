;;; (murdoch testing harness): a test killed leaves none of its children,
;;; so a time limit or a person's kill -9 of a test or bench leaves no lab
;;; running.
(import (scheme base) (scheme file) (scheme read) (scheme write) (chibi test)
        (only (chibi process) kill signal/kill)
        (only (chibi filesystem) delete-file-hierarchy)
        (murdoch testing harness))

(define dir (temporary-directory))
(define pid-file (string-append dir "/child.pid"))

;; A test of its own, as a program: starts a long sleep by start-process!,
;; writes the sleep's pid, and waits.
(define script (string-append dir "/parent.scm"))
(call-with-output-file script
  (lambda (out)
    (write '(import (scheme base) (scheme file) (scheme write) (srfi 18)
                    (only (chibi filesystem) rename-file) (murdoch testing harness))
           out)
    (write `(let ((pid (start-process! '("sleep" "300") ,(string-append dir "/sleep.log"))))
              (call-with-output-file ,(string-append pid-file ".new")
                (lambda (out) (write pid out)))
              (rename-file ,(string-append pid-file ".new") ,pid-file)
              (thread-sleep! 300))
           out)))

;; Whether process pid runs: a zombie, ended but not yet reaped by its new
;; parent, does not.
(define (running? pid)
  (let ((stat (string-append "/proc/" (number->string pid) "/stat")))
    (and (file-exists? stat)
         (let ((text (guard (e (#t "")) (file-text stat))))
           (not (text-contains? text ") Z "))))))

(test-begin "harness")

(test-group "a test killed takes its children with it"
  (let* ((parent (start-process! (list (tool-path "tools/chibi") script)
                                 (string-append dir "/parent.log")))
         (child (and (wait-until 60 (lambda () (file-exists? pid-file)))
                     (call-with-input-file pid-file read))))
    (test-assert "the test started its child" (and child (running? child)))
    (kill-process! parent)
    (test "the child is gone once the test is killed" #f
      (and child (not (wait-until 30 (lambda () (not (running? child)))))))
    (if (and child (running? child)) (kill child signal/kill))))

(delete-file-hierarchy dir)
(test-end)
