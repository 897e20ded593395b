;;; The lab file's settings: one table of names, defaults and checks
;;; (lib/murdoch/lab.scm), read once, every mistake named with its clause.
(import (scheme base) (scheme write) (scheme file) (chibi test)
        (only (chibi filesystem) delete-file-hierarchy)
        (murdoch lab) (murdoch testing))

(define dir (temporary-directory))
(define file (string-append dir "/lab.scm"))

;; The lab whose clauses are text, read; or the message of its error.
(define (read-text text)
  (call-with-output-file file (lambda (out) (write-string text out)))
  (guard (e ((error-object? e) (error-object-message e)))
    (read-lab file)))

(define (setting text key)
  (let ((lab (read-text text)))
    (if (lab? lab) (lab-setting lab key) lab)))

(define (says? text what)
  (let ((message (read-text text)))
    (and (string? message) (text-contains? message what))))

(test-begin "lab-file")

(test-group "defaults come from the table"
  (test 5 (setting "(lab x)" 'timeout))
  (test 4000 (setting "(lab x)" 'max-depth))
  (test '(broadcast) (setting "(lab x)" 'delivery))
  (test '() (setting "(lab x)" 'code))
  (test (* 512 1024 1024) (setting "(lab x)" 'heap-max)))

(for-each (lambda (name)
            (call-with-output-file (string-append dir "/" name)
              (lambda (out) (write-string "(define x 1)\n" out))))
          '("a.scm" "b.scm"))

(test-group "what the file says is read"
  (test 2.5 (setting "(lab x (timeout 2.5))" 'timeout))
  (test (* 160 1024 1024) (setting "(lab x (heap-max \"160M\"))" 'heap-max))
  (test '(multicast "239.1.1.1" 5000)
    (setting "(lab x (delivery multicast \"239.1.1.1\" 5000))" 'delivery))
  (test '("a.scm" "b.scm") (setting "(lab x (code \"a.scm\" \"b.scm\"))" 'code)))

(test-group "mistakes are named, with their clause"
  (test "an unknown setting, with the nearest" #t
    (says? "(lab x (timout 3))" "(timout 3): no such setting; did you mean timeout?"))
  (test "one far from any" #t
    (says? "(lab x (colour blue))" "(colour blue): no such setting"))
  (test "a wrong value" #t
    (says? "(lab x (timeout -1))" "(timeout -1): timeout takes a positive number of seconds"))
  (test "too many values" #t
    (says? "(lab x (lease 1 2))" "(lease 1 2): lease takes a positive number of seconds"))
  (test "a max-depth past what Chibi's writer keeps" #t
    (says? "(lab x (max-depth 20000))" "max-depth takes a whole number from 1 to 9000"))
  (test "a size that is none" #t
    (says? "(lab x (heap-max \"12Q\"))" "heap-max takes bytes"))
  (test "a delivery that is neither" #t
    (says? "(lab x (delivery carrier-pigeon))" "delivery takes broadcast, or multicast"))
  (test "the file is named" #t (says? "(lab x (timout 3))" file))
  (test "two address spaces of one name" #t
    (says? "(lab x (aspace a) (aspace b) (aspace a))" "(aspace a): two address spaces of this name"))
  (test "two things on one port" #t
    (says? "(lab x (port-base 7000) (aspace a) (aspace b (port 7000)))"
           "(port 7000): two things on this port"))
  (test "a robot's trip server on an address space's port" #t
    (says? "(lab x (port-base 7000) (aspace a (robot (trip-port 7001))) (aspace b))"
           "(port 7001): two things on this port"))
  (test "a code file that is not there" #t
    (says? "(lab x (code \"nowhere.scm\"))" "(code \"nowhere.scm\"): no such file")))

(test-end)
(delete-file-hierarchy dir)
(test-exit)
