;;; The cases of the box team (examples/box-move.scm, docs/box-move.md),
;;; included by tests/box-move*-test.scm, one case each, which tests/run
;;; runs one by one: each case is
;;; `make demo-box`'s run, in the lab's fast-forward simulator, on a port
;;; base of its own, judged by examples/box-judge.scm from the simulator's
;;; own word: the box must end within 300 mm of the path's goal and 20
;;; degrees of its heading, and with a fault the spare, the robot the lost
;;; pusher's component went to, must have been at the box's rear face for
;;; the last third of the distance the box moved.  A lab with no spare
;;; (box-case's third argument #f) is judged by where the box ended, and
;;; the task must say that the lost pusher's component failed with no
;;; other robot to take it.  The including file imports what it needs.

;; The demo's output, and whether it exited 0, for LAB with FAULT ("" for
;; none, or a role: inside, outside).  Its robots steer in real time
;; against the simulator's clock, so it runs ahead of the tests beside it
;; (nice -10, as root; as another user nice says it cannot, and the demo
;; runs as usual): two runs of the suite at once once left the spare of
;; FAULT=2 too late at the box.
(define (run-demo lab fault)
  (let* ((dir (temporary-directory)) (out (string-append dir "/demo.out"))
         (status
          (system? "sh" "-c"
                   (string-append
                    "cd \"$0\" && MURDOCH_PORT_BASE=$1 MURDOCH_DEMO_FAULT=$4"
                    " MURDOCH_DEMO_TASK=\"$2/examples/pose-box-move.scm\""
                    " MURDOCH_DEMO_JUDGE=\"$2/examples/box-judge.scm\""
                    " nice -n -10 timeout -s KILL 280 \"$2/bin/murdoch\" demo \"$2/$5\" >\"$3\" 2>&1")
                   dir (number->string (free-port-base dir)) (tool-path ".") out
                   fault lab))
         (text (file-text out)))
    (delete-file-hierarchy dir)
    (cons status text)))

;; The number after "bench: NAME " in text, or #f.
(define (bench text name)
  (let ((prefix (string-append "bench: " name " ")))
    (any (lambda (line)
           (and (>= (string-length line) (string-length prefix))
                (string=? prefix (substring line 0 (string-length prefix)))
                (read (open-input-string (substring line (string-length prefix)
                                                    (string-length line))))))
         (text-lines text))))

;; One case: LAB's demo with FAULT, its assertions in a group of their own;
;; spare? (by default #t) whether LAB has a robot to take a lost pusher's
;; place.
(define (box-case lab fault . spare?)
  (let* ((run (run-demo lab fault)) (status (car run)) (text (cdr run))
         (name (if (string=? fault "") "box-move" "box-move-fault"))
         (spare? (or (null? spare?) (car spare?))))
    (test-group (string-append lab (if (string=? fault "")
                                       ""
                                       (string-append ", " fault " pusher killed")))
      (test "the box arrives: within 300 mm of the goal and 20 degrees of its heading" #t
        (text-contains? text "within 300 mm and 20 degrees"))
      (test-assert "its goal error, a bench line, is at most 300 mm"
        (let ((mm (bench text (string-append name "-goal-error-mm"))))
          (and (real? mm) (<= mm 300))))
      (test-assert "both steps ran, the second to its end"
        (text-contains? text ": step 2 done: ("))
      (if (not (string=? fault ""))
          (test-assert "a pusher was killed"
            (text-contains? text "demo: FAULT: killing ")))
      (cond ((string=? fault ""))
            (spare?
             (test-assert "its component went to a spare"
               (text-contains? text " reassigned from "))
             (test "the spare pushed for the last third of the way" #t
               (text-contains? text ": it pushed"))
             (test-assert "box-move-spare-push-mm, a bench line, is above nought"
               (let ((mm (bench text "box-move-spare-push-mm")))
                 (and (real? mm) (> mm 0)))))
            (else
             (test-assert "the task says the lost pusher's part failed, no robot left"
               (text-contains? text "connection lost; no other capable robot is free"))
             (test-assert "the other pusher finished its part of step 2"
               (let ((done (find (lambda (line) (text-contains? line ": step 2 done: "))
                                 (text-lines text)))
                     (other (if (string=? fault "inside") " outside)" " inside)")))
                 (and done (text-contains? done other))))))
      ;; With no spare the task fails, as it must, for one of its parts did.
      (test "the demo says so by its exit status" spare? status))
    (if (not (and (eq? status spare?) (text-contains? text "within 300 mm and 20")))
        (show-failed-run text))))

;; A failed run's output, its judge's verdict first: tests/run shows only
;; a few lines after a failure.
(define (show-failed-run text)
  (newline)
  (for-each (lambda (line)
              (if (text-contains? line "box-move: ") (begin (display line) (newline))))
            (text-lines text))
  (display text))
