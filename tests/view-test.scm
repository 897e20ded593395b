;;; The live view: its parts (the room, the task table, a box seen by a
;;; fiducial finder), then a real lab with --view, read over HTTP and as
;;; server-sent events, and shown in a real browser, headless chromium:
;;; the page names each robot and the task panel names the task and the
;;; robot that won it.  A replay of the run's trace shows the same.
(import (scheme base) (scheme write) (scheme file) (scheme char) (scheme process-context)
        (srfi 1) (srfi 18) (chibi test)
        (only (chibi process) system?)
        (only (chibi filesystem) delete-file-hierarchy file-size directory-files
              current-directory change-directory)
        (chibi json)
        (murdoch lab) (murdoch view) (murdoch wire connect) (murdoch testing harness))

(define (assq-ref key alist) (cdr (assq key alist)))

(test-begin "view")

;;; The parts

(define lab
  (make-test-lab
   '((aspace moseley (robot (pose -1000 0 0)) (capabilities mobile))
     (aspace ernst (robot (pose 1000 -1500 90)) (capabilities mobile))
     (aspace troy (position 0 2500 0))
     (world (wall -3000 -3000 3000 -3000) (wall 3000 -3000 3000 3000)
            (wall 3000 3000 -3000 3000 80) (wall -3000 3000 -3000 -3000)
            (box 1500 1500 400 400 30)))))
(define dir (test-lab-directory lab))
(define (in-dir name) (string-append dir "/" name))

(test-group "the room: the trace's first line"
  (let ((header (string->json (json-text (lab-header (read-lab (test-lab-file lab)))))))
    (test "the lab's name" "test" (assq-ref 'lab header))
    (test "walls, 50 mm thick unless said"
        '(#(-3000 -3000 3000 -3000 50) #(3000 3000 -3000 3000 80))
      (let ((walls (vector->list (assq-ref 'walls header))))
        (list (first walls) (third walls))))
    (test "boxes" '#(#(1500 1500 400 400 30)) (assq-ref 'boxes header))
    (test "the robots' radius" 180 (assq-ref 'radius header))
    ;; Chibi's current-second is TAI, 37 s ahead of the clock on the wall.
    (test "started: seconds since 1970, UTC, as date says" #t
      (< (abs (- (assq-ref 'started header)
                 (string->number (command-output (list "date" "+%s")))))
         10))
    (test "which address spaces are robots"
        '(("moseley" . #t) ("ernst" . #t) ("troy" . #f))
      (map (lambda (a) (cons (assq-ref 'name a) (assq-ref 'robot a)))
           (vector->list (assq-ref 'aspaces header))))))

(test-group "two views of one lab, started in one second, have a trace each"
  (let ((here (current-directory)))
    (change-directory dir)
    (let* ((lab (read-lab (test-lab-file lab)))
           (a (default-trace lab))
           (b (default-trace lab)))
      (change-directory here)
      (test "two names" #t (not (equal? a b)))
      (test "each a file made for it" '(#t #t)
        (map (lambda (f) (file-exists? (in-dir f))) (list a b))))))

;; "#1565c0" ... in the order text holds them.
(define (hex-colours text)
  (let loop ((i 0) (acc '()))
    (cond ((> (+ i 9) (string-length text)) (reverse acc))
          ((and (char=? (string-ref text i) #\") (char=? (string-ref text (+ i 1)) #\#)
                (char=? (string-ref text (+ i 8)) #\"))
           (loop (+ i 9) (cons (substring text (+ i 1) (+ i 8)) acc)))
          (else (loop (+ i 1) acc)))))

(test-group "the simulator's SVG: the view's colours, and the robots' names"
  (test "one palette in both"
      (take (hex-colours (file-text (tool-path "web/view.js"))) 10)
    (let* ((c (file-text (tool-path "sim/trace.c")))
           (from (let loop ((i 0))
                   (if (string=? "colour(const world" (substring c i (+ i 18)))
                       i
                       (loop (+ i 1))))))
      (take (hex-colours (substring c from (string-length c))) 10)))
  (let* ((svg (in-dir "sim.svg"))
         (log (in-dir "b14.log"))
         (pid (start-process! (list (tool-path "sim/b14") (test-lab-file lab)
                                    "--lock-dir" (in-dir "locks") "--trace" svg)
                              log)))
    (wait-until 60 (lambda () (text-contains? (file-text log) "b14: ready")))
    (thread-sleep! 1)                   ; a step or more, for a sample
    (stop-process! pid)
    (let ((text (file-text svg)))
      (test "each robot named" '(#t #t)
        (map (lambda (name) (text-contains? text (string-append ">" name "</text>")))
             '("moseley" "ernst")))
      (test "each in its view colour: moseley first, ernst second" '(#t #t)
        (map (lambda (colour)
               (text-contains? text
                               (string-append "<circle r=\"180\" fill=\"" colour "\"")))
             '("#1565c0" "#c62828"))))))

(test-group "a box where a robot's fiducial finder sees it"
  (define (mm ls) (map (lambda (x) (exact (round x))) ls))
  (test "to the right of a robot facing +y, turned" '(2500 0 120)
    (mm (box-seen '(1000 0 90 0) 1500 -90 30)))
  (test "to the left of a robot facing +x" '(0 2000 0)
    (mm (box-seen '(0 0 0 0) 2000 90 0))))

(test-group "reservation names and task ids"
  (test '("dual-sonar-task" "pose-12") (reservation-task "dual-sonar-task@pose-12/3"))
  (test '("box@move" "tester") (reservation-task "box@move@tester/2"))
  (test '("plain" #f) (reservation-task "plain")))

;; A report as aspace-report makes it: (UID UP-SINCE POSE BATTERY HELD TASKS
;; GOAL ENDED).
(define (report uid held tasks . ended) (list uid 0 '(0 0 0 0) 136 held tasks #f
                                              (if (pair? ended) (car ended) '())))

(define (components table)
  (map (lambda (t)
         (cons (assq-ref 'name t)
               (map (lambda (c)
                      (list (assq-ref 'index c) (assq-ref 'robot c)
                            (vector->list (assq-ref 'subjects c))
                            (assq-ref 'until c) (assq-ref 'end c) (assq-ref 'from c)))
                    (vector->list (assq-ref 'components t)))))
       (table-tasks table)))

;; The tasks of the view's task table, as the page reads them.
(define (table-tasks table)
  (vector->list (string->json (json-text (task-table->json table 10)))))

;; The newest task of table, as the JSON reader reads it, and its state.
(define (newest-task table) (car (table-tasks table)))
(define (task-state table) (assq-ref 'state (newest-task table)))

;; A look at time t that finds each robot of robot-reports, (UID REPORT).
(define (look table t . robot-reports) (task-table-update! table t robot-reports))
(define (robot uid held tasks . ended) (list uid (apply report uid held tasks ended)))

(test-group "a detached task shows its coordinator and standby"
  (let ((table (make-task-table)))
    (task-table-update!
     table 1
     (list (list 'praline
                 (append (report 'praline '() '((posed survey@praline/1 running)))
                         (list '((survey@praline/1 coordinator 1 running praline troy
                                  guest-7 #f)))))
           (list 'troy
                 (append (report 'troy '() '())
                         (list '((survey@praline/1 standby 1 running praline troy
                                  guest-7 #f)))))))
    (test "as its coordinator says" '("praline" "troy" "running")
      (let ((t (newest-task table)))
        (list (assq-ref 'coordinator t) (assq-ref 'standby t) (assq-ref 'state t))))))

(test-group "the task table"
  (let ((table (make-task-table)))
    ;; pose-task negotiating: the candidates hold their exclusive subjects.
    (task-table-update! table 1
                        (list (list 'moseley
                                    (report 'moseley
                                            '((mobile t@pose-1/1) (sonar t@pose-1/1))
                                            '()))
                              (list 'ernst (report 'ernst '((mobile t@pose-1/1)) '()))))
    (test "a subject held for a task that runs nothing there is a reservation, unnumbered"
        '(("t" (null "moseley" ("mobile" "sonar") null null null)
               (null "ernst" ("mobile") null null null)))
      (components table))
    (test "the task negotiates" "negotiating" (task-state table))
    (task-table-update! table 2 (list (list 'moseley (report 'moseley '() '()))))
    (test "a reservation no longer held was released; one whose robot did not answer, not"
        '(("t" (null "moseley" ("mobile" "sonar") 2 "released" null)
               (null "ernst" ("mobile") null null null)))
      (components table))
    (task-table-update! table 3 (list (list 'moseley (report 'moseley '() '()))))
    (task-table-update! table 4 (list (list 'moseley (report 'moseley '() '()))))
    (test "one silent for three looks in a row was lost, and its task failed"
        '(("t" (null "moseley" ("mobile" "sonar") 2 "released" null)
               (null "ernst" ("mobile") 4 "lost: ernst does not answer" null)))
      (components table))
    (test "the task's state" "failed" (task-state table))
    ;; A robot killed and started again answers at once, holding nothing.
    (let ((table (make-task-table)))
      (task-table-update! table 1
                          (list (list 'moseley
                                      (report 'moseley '((mobile u@pose-3/1)) '()))))
      (task-table-update! table 2
                          (list (list 'moseley
                                      (cons* 'moseley 99
                                             (cddr (report 'moseley '() '()))))))
      (test "one that started again lost what it ran"
          '(("u" (null "moseley" ("mobile") 2 "lost: moseley started again" null)))
        (components table)))
    ;; start-task: components by index, and a reassignment.
    (let ((table (make-task-table)))
      (task-table-update!
       table 1
       (list (list 'moseley (report 'moseley '((mobile |s@tester/4|))
                                    '((running |s@tester/1| 1 tester))))
             (list 'tester (report 'tester '() '((posed |s@tester/1| running))))))
      (task-table-update!
       table 2
       (list (list 'moseley (report 'moseley '() '()))
             (list 'ernst (report 'ernst '() '((running |s@tester/1| 1 tester))))
             (list 'tester (report 'tester '() '((posed |s@tester/1| running))))))
      (test "a component that moves to another robot was reassigned from the first"
          '(("s" (1 "moseley" ("mobile") 2 "moved to ernst" null)
                 (1 "ernst" () null null "moseley")))
        (components table))
      (test "the task's state is what its poser says" "running" (task-state table))
      (task-table-update! table 3 (list (list 'ernst (report 'ernst '() '()))
                                        (list 'tester (report 'tester '() '())
                                              '((posed |s@tester/1| cancelled)))))
      (test "to its end, when the report leaves a task that is over out" "cancelled"
        (task-state table))))
  ;; pose-task's components, as their robots list them (run-posed-component).
  (let ((table (make-task-table)))
    (look table 1 (robot 'moseley '((mobile p@guest-1/1)) '()))
    (look table 2
          (robot 'moseley '((mobile p@guest-1/1)) '((running p@guest-1/1 1 guest-1)))
          (robot 'ernst '() '((running p@guest-1/1 2 guest-1))))
    (test "each component by its number; a reservation becomes the component run under it"
        '(("p" (1 "moseley" ("mobile") null null null) (2 "ernst" () null null null)))
      (components table))
    (test "seen since its reservation was" '(1 2)
      (map (lambda (c) (assq-ref 'since c))
           (vector->list (assq-ref 'components (newest-task table)))))
    (test "running" "running" (task-state table))
    ;; Component 1 raised; a third, on troy, began and ended between two looks.
    (look table 4
          (robot 'moseley '() '()
                 '((p@guest-1/1 1 guest-1 2.5 0.5 (failed "car: not a pair ()"))))
          (robot 'ernst '() '((running p@guest-1/1 2 guest-1)))
          (robot 'troy '() '()
                 '((p@guest-1/1 3 guest-1 1 0.5 (done))
                   (old@guest-1/1 1 guest-1 9 8 (done)))))
    (test (string-append "a component ends as its robot says, which is what its poser"
                         " was told; one that ran between two looks is there, with its"
                         " times")
        '(("p" (1 "moseley" ("mobile") 3.5 "failed: car: not a pair ()" null)
               (2 "ernst" () null null null)
               (3 "troy" () 3.5 "done" null)))
      (components table))
    (test "one that ended before the view started is left out" '("p")
      (map car (components table)))
    (test "a task runs while a component does" "running" (task-state table))
    (look table 5
          (robot 'moseley '() '())
          (robot 'ernst '() '() '((p@guest-1/1 2 guest-1 4 0.2 (done))))
          (robot 'troy '() '()))
    (test "and then failed, as its poser saw it" "failed" (task-state table)))
  ;; A started task whose poser is a guest: lost on moseley, done on ernst.
  (let ((table (make-task-table)))
    (look table 1 (robot 'moseley '() '((running r@guest-3/1 1 guest-3))))
    (look table 2
          (robot 'moseley '() '() '((r@guest-3/1 1 guest-3 1.5 0.5 (lost "stalled"))))
          (robot 'ernst '() '((running r@guest-3/1 1 guest-3))))
    (look table 3
          (robot 'moseley '() '())
          (robot 'ernst '() '() '((r@guest-3/1 1 guest-3 1.5 0.5 (done)))))
    (test "a component lost on one robot and done on the next is done, and so its task"
        '(("r" (1 "moseley" () 1.5 "lost: stalled" null)
               (1 "ernst" () 2.5 "done" "moseley"))
          "done")
      (list (car (components table)) (task-state table))))
  (let ((table (make-task-table)))
    (look table 1 (robot 'moseley '((mobile n@guest-2/1)) '()))
    (look table 2 (robot 'moseley '() '()))
    (test "a task whose robots were only reserved, then released, never started"
        "not started" (task-state table))))

;; An answer of remote-apply-all to report-source, from a robot at pose.
(define (answer uid pose ranges fiducials . goal)
  (list uid #t (list (list uid 0 pose 136 '() '() (and (pair? goal) (car goal)))
                     ranges fiducials)))

(test-group "snapshots"
  (let* ((the-lab (read-lab (test-lab-file lab)))
         (state (new-view-state (lab-header the-lab)))
         (snap (lambda (t answers)
                 (string->json (json-text (view-snapshot the-lab t answers state)))))
         (moseley (lambda (s) (vector-ref (assq-ref 'aspaces s) 0)))
         (ring (make-list 16 1000)))
    (snap 0 (list (answer 'moseley '(0 0 0 0) ring #f)))
    (let ((s (snap 1 (list (answer 'moseley '(500 0 0 0) ring '((0 1000 0 0)))))))
      (test "a sonar ring read again is drawn from where it was first read" '#(0 0 0)
        (assq-ref 'sonar-at (moseley s)))
      (test "a box a robot sees is where it sees it" '#(1500 0 400 400 0)
        (vector-ref (assq-ref 'boxes s) 0)))
    (let ((s (snap 2 (list (answer 'moseley '(800 0 0 0) (make-list 16 900) #f
                                   '(900 50))))))
      (test "a new ring is drawn from the pose it came with" '#(800 0 0)
        (assq-ref 'sonar-at (moseley s)))
      (test "a robot's goto target is drawn" '#(900 50) (assq-ref 'goal (moseley s))))
    (test "an address space that did not answer is away, and why" '(#t "no answer")
      (let ((a (vector-ref (assq-ref 'aspaces
                                     (snap 3 (list (list 'ernst #f "no answer"))))
                           0)))
        (list (assq-ref 'away a) (assq-ref 'why a))))))

;;; A real lab

;; The body of an HTTP GET of path on port, or #f.
(define (http-get port path)
  (let ((io (open-connection "127.0.0.1" port 5)))
    (and (pair? io)
         (let ((in (car io)) (out (cadr io)))
           (write-string (string-append "GET " path
                                        " HTTP/1.0\r\nHost: localhost\r\n\r\n")
                         out)
           (flush-output-port out)
           (let loop ((acc '()))
             (let ((s (read-string 65536 in)))
               (if (eof-object? s)
                   (begin (close-port in) (close-port out)
                          (let* ((all (apply string-append (reverse acc)))
                                 (end (string-search "\r\n\r\n" all)))
                            (and end (substring all (+ end 4) (string-length all)))))
                   (loop (cons s acc)))))))))

(define (string-search word text)
  (let ((n (string-length word)))
    (let loop ((i 0))
      (cond ((> (+ i n) (string-length text)) #f)
            ((string=? word (substring text i (+ i n))) i)
            (else (loop (+ i 1)))))))

;; The first n events of /events?from=0, as (ID . DATA), or timeout.
(define (first-events port n)
  (let ((t (make-thread
            (lambda ()
              (let* ((io (open-connection "127.0.0.1" port 5))
                     (in (car io)) (out (cadr io)))
                (write-string "GET /events?from=0 HTTP/1.1\r\nHost: localhost\r\n\r\n"
                              out)
                (flush-output-port out)
                (let loop ((events '()) (id #f))
                  (if (= (length events) n)
                      (begin (close-port in) (close-port out) (reverse events))
                      (let ((line (read-line in)))
                        (cond ((eof-object? line) (reverse events))
                              ((string-prefix? "id: " line)
                               (loop events (string->number (string-copy line 4))))
                              ((string-prefix? "data: " line)
                               (loop (cons (cons id (string-copy line 6)) events) #f))
                              (else (loop events id)))))))))))
    (thread-start! t)
    (thread-join! t 20 'timeout)))

(define (string-prefix? p s)
  (and (>= (string-length s) (string-length p))
       (string=? p (substring s 0 (string-length p)))))

(define chromium
  (find (lambda (c) (system? "sh" "-c" (string-append "command -v " c " >/dev/null")))
        '("chromium" "chromium-browser" "google-chrome")))

;; $1 is a folder of chromium's own.
(define chromium-flags
  "--headless --no-sandbox --disable-gpu --user-data-dir=\"$1\"")

;; The page's DOM once its scripts ran, as headless chromium dumps it.
(define (browser-dom url file)
  (system? "sh" "-c"
           (string-append "timeout 120 \"$0\" " chromium-flags
                          " --virtual-time-budget=4000 --dump-dom \"$2\""
                          " >\"$3\" 2>/dev/null")
           chromium (in-dir "chromium") url file)
  (file-text file))

(define (screenshot url file)
  (system? "sh" "-c"
           (string-append "timeout 120 \"$0\" " chromium-flags
                          " --hide-scrollbars --window-size=1400,900"
                          " --virtual-time-budget=4000 --screenshot=\"$3\" \"$2\""
                          " >/dev/null 2>&1")
           chromium (in-dir "chromium") url file))

;; The points of the path of robot name the page drew.
(define (path-points dom name)
  (let* ((tag (string-append "<polyline data-name=\"" name "\" points=\""))
         (at (string-search tag dom)))
    (if at
        (let* ((start (+ at (string-length tag)))
               (end (+ start (string-search "\"" (string-copy dom start)))))
          (delete-duplicates (text-words (substring dom start end))))
        '())))

(define (text-words s)
  (let loop ((chars (string->list s)) (word '()) (acc '()))
    (cond ((null? chars)
           (reverse (if (null? word) acc (cons (list->string (reverse word)) acc))))
          ((char=? (car chars) #\space)
           (loop (cdr chars) '()
                 (if (null? word) acc (cons (list->string (reverse word)) acc))))
          (else (loop (cdr chars) (cons (car chars) word) acc)))))

(define view-port (+ (test-lab-port-base lab) 148))

(define (write-task name text)
  (call-with-output-file (in-dir name) (lambda (out) (write-string text out))))

;; `murdoch pose` of the task file name, its output in NAME.out; its pid.
(define (start-pose! name)
  (start-process! (list "timeout" "60" (tool-path "bin/murdoch") "pose"
                        (test-lab-file lab) (in-dir name))
                  (in-dir (string-append name ".out"))))

;; The task named name in the view's snapshot, or #f.
(define (task-named-in snapshot name)
  (find (lambda (t) (equal? name (assq-ref 'name t)))
        (vector->list (assq-ref 'tasks snapshot))))

;; The task named name in the view's newest snapshot, once it is over
;; (at most 20 s), or #f.
(define (task-over state name)
  (wait-until 20
    (lambda ()
      (let ((t (task-named-in (state) name)))
        (and t (member (assq-ref 'state t) '("done" "failed")) t)))))

;; (INDEX ROBOT END) of each component of task t.
(define (component-ends t)
  (map (lambda (c) (list (assq-ref 'index c) (assq-ref 'robot c) (assq-ref 'end c)))
       (vector->list (assq-ref 'components t))))

;; The robot that the pose's output in file says component k starts on.
(define (starts-on file k)
  (let ((word (string-append "component " (number->string k) " starts on ")))
    (any (lambda (line)
           (let ((at (string-search word line)))
             (and at (substring line (+ at (string-length word)) (string-length line)))))
         (if (file-exists? file) (read-lines file) '()))))

;; A task that troy, an address space of the lab, starts and waits for
;; (the task file does so before it answers a task of no components to
;; pose): the view takes troy's word on it, and troy's report leaves out
;; the tasks that are over.
(define (posed-in-the-lab state)
  (write-task "in-the-lab.scm"
              "(begin
                 (remote-apply (uid->aspace 'troy)
                               (lambda ()
                                 (task-wait
                                  (start-task 'lab-posed 1
                                              (list (list (list 'mobile) '()))
                                              (list #f)
                                              (list (lambda () (thread-sleep! 2) 'ok))))
                                 #t))
                 (list 'nothing 0 '() '() '()))\n")
  (reap! (start-pose! "in-the-lab.scm"))
  (let ((t (task-over state "lab-posed")))
    (test "a task posed in the lab ends in the state its poser gives it" '("troy" "done")
      (and t (list (assq-ref 'poser t) (assq-ref 'state t))))))

;; pose-task posed by `murdoch pose`, a guest the view does not ask: each
;; component is shown by its number, the one that holds no subject too,
;; and each ends as the pose saw it -- failed by raising, on a robot
;; that lives on; lost, on a robot that was killed.
(define (posed-from-a-guest lab-pid state)
  (write-task "trip-up.scm"
              "(list 'trip-up 2 (list (list (list 'mobile) '()) (list '() (list 'mobile)))
                     (list #f #f)
                     (list (lambda () (thread-sleep! 1) (car '())) (lambda () 'fine)))\n")
  (reap! (start-pose! "trip-up.scm"))
  (let ((first (starts-on (in-dir "trip-up.scm.out") 1))
        (second (starts-on (in-dir "trip-up.scm.out") 2))
        (t (task-over state "trip-up")))
    (test (string-append "pose-task's components by their numbers; the one that holds"
                         " no subject is there; the one that raised failed, as its"
                         " poser saw")
        (list (list 1 first "failed: car: not a pair ()") (list 2 second "done"))
      (and t (component-ends t)))
    (test "and so did its task" "failed" (and t (assq-ref 'state t))))
  (write-task "cut-off.scm"
              "(list 'cut-off 1 (list (list (list 'mobile) '())) (list #f)
                     (list (lambda () (thread-sleep! 30) 'slept)))\n")
  (let* ((pose (start-pose! "cut-off.scm"))
         (winner (wait-until 30 (lambda () (starts-on (in-dir "cut-off.scm.out") 1)))))
    ;; Killed once the view has seen it run, by its number, on the
    ;; winner: a robot that dies takes with it what the view had not yet
    ;; seen (the task alone seen, a loaded machine once left the view its
    ;; robot's reservation, with no number).
    (wait-until 20 (lambda ()
                     (let ((t (task-named-in (state) "cut-off")))
                       (and t (member (list 1 winner)
                                      (map (lambda (c) (list (car c) (cadr c)))
                                           (component-ends t)))))))
    (system? (tool-path "tools/kill-aspace") (number->string lab-pid) (or winner "none"))
    (reap! pose)
    (let ((t (task-over state "cut-off")))
      (test "the pose whose robot was killed: its component lost, its task failed"
          (list (list 1 winner #t) "failed")
        (and t (list (let ((c (car (component-ends t))))
                       (list (car c) (cadr c) (text-contains? (car (cddr c)) "lost: ")))
                     (assq-ref 'state t))))
      (test "as its poser was told" #t
        (text-contains? (file-text (in-dir "cut-off.scm.out"))
                        (string-append "(error " (or winner "none")
                                       " \"connection lost\")")))
      ;; The lab starts the robot again; the page is tried once it is back.
      (wait-until 30 (lambda ()
                       (not (any (lambda (a) (assq-ref 'away a))
                                 (vector->list (assq-ref 'aspaces (state))))))))))

(if (not (file-exists? (tool-path "sim/b14")))
    (begin (display "no simulator (make -C sim): the lab part is left out\n"))
    (let ((pid (start-murdoch-lab!
                (list (test-lab-file lab) "--logs" (in-dir "logs") "--view")
                (in-dir "lab.out"))))
      (test "the lab says where the view is" #t
        (text-contains? (file-text (in-dir "lab.out"))
                        (string-append "lab: view at http://127.0.0.1:"
                                       (number->string view-port) "/")))
      (test "ps names it murdoch-view" #t
        (not (equal? "0" (command-output
                          (list "sh" "-c" "ps -eo comm | grep -c '^murdoch-view$'")))))
      (test "the page" #t (text-contains? (or (http-get view-port "/") "") "view.js"))
      (test "the trace starts with the room" "test"
        (assq-ref 'lab (string->json (car (text-lines (http-get view-port "/trace"))))))
      (let ((events (first-events view-port 3)))
        (test "server-sent events: snapshots 0, 1, 2" '(0 1 2)
          (if (list? events) (map car events) events))
        (test "each a snapshot of every address space" '("moseley" "ernst" "troy")
          (if (list? events)
              (map (lambda (a) (assq-ref 'name a))
                   (vector->list (assq-ref 'aspaces (string->json (cdr (car events))))))
              events)))
      ;; A task that drives one robot for a while.
      (call-with-output-file (in-dir "task.scm")
        (lambda (out)
          (write-string "(start-task 'drive-a-while 1
                          (list (list (list 'mobile) '())) (list #f)
                          (list (lambda ()
                                  (goto-xy '(0 -1000))
                                  (thread-sleep! 1)
                                  (local-aspace-uid))))\n"
                        out)))
      (system? "sh" "-c" "timeout 60 \"$0\" pose \"$1\" \"$2\" >\"$3\" 2>&1"
               (tool-path "bin/murdoch") (test-lab-file lab) (in-dir "task.scm")
               (in-dir "pose.out"))
      ;; The result is the line before pose's last, which says how it ended.
      (let ((winner (let ((lines (read-lines (in-dir "pose.out"))))
                      (if (> (length lines) 1) (list-ref lines (- (length lines) 2)) "")))
            (state (lambda () (string->json (http-get view-port "/state")))))
        (test "the task ran on a robot" #t
          (and (member winner '("(moseley)" "(ernst)")) #t))
        (let ((winner (if (> (string-length winner) 2)
                          (substring winner 1 (- (string-length winner) 1))
                          winner)))
          (test "the view's state has the task, and who won it"
              (list "drive-a-while" winner)
            (let ((tasks (vector->list (assq-ref 'tasks (state)))))
              (if (null? tasks)
                  tasks
                  (list (assq-ref 'name (car tasks))
                        (assq-ref 'robot
                                  (vector-ref (assq-ref 'components (car tasks)) 0))))))
          (test "while it drove, the trace has its goto target" #t
            (any (lambda (line)
                   (let ((s (string->json line)))
                     (and (equal? "state" (assq-ref 'kind s))
                          (any (lambda (a) (and (equal? winner (assq-ref 'name a))
                                                (equal? '#(0 -1000) (assq-ref 'goal a))))
                               (vector->list (assq-ref 'aspaces s))))))
                 (cdr (text-lines (http-get view-port "/trace")))))
          (posed-from-a-guest pid state)
          (posed-in-the-lab state)
          (if (not chromium)
              (display (string-append "skipped: no chromium on this machine, so the page"
                                      " is not tried in a browser\n"))
              (let ((dom (browser-dom
                          (string-append "http://127.0.0.1:" (number->string view-port)
                                         "/?poll=300")
                          (in-dir "live.html"))))
                (test "in the browser: the lab's name" #t (text-contains? dom "lab test"))
                (test "each name drawn in the room, robots' and the workstation's"
                    '(#t #t #t)
                  (map (lambda (n) (text-contains? dom (string-append ">" n "</text>")))
                       '("moseley" "ernst" "troy")))
                (test "each name in the table of address spaces" '(#t #t #t)
                  (map (lambda (n)
                         (text-contains? dom (string-append "<tr data-name=\"" n "\"")))
                       '("moseley" "ernst" "troy")))
                (test "the task panel names the task" #t
                  (text-contains? dom "<span class=\"task-name\">drive-a-while</span>"))
                (test "and the robot that won it" #t
                  (text-contains? dom (string-append ">" winner "</td>")))
                (test "the winner's path: more than one point" #t
                  (> (length (path-points dom winner)) 1))
                (test "a clock" #t (text-contains? dom "t = "))
                (test "pose-task's components by number, one that holds nothing too"
                    '(#t #t)
                  (map (lambda (k)
                         (text-contains? dom (string-append "<td>" k
                                                            "</td><td class=\"winner\"")))
                       '("1" "2")))
                (test "a component failed as its poser saw it" #t
                  (text-contains? dom "<td>failed: car: not a pair ()</td>"))
                (let ((shot (string-append (or (get-environment-variable "TMPDIR") "/tmp")
                                           "/murdoch-view-test.png")))
                  (screenshot (string-append "http://127.0.0.1:"
                                             (number->string view-port) "/?poll=300")
                              shot)
                  (test "a screenshot" #t
                    (and (file-exists? shot) (> (file-size shot) 1000)))
                  (display (string-append "screenshot: " shot "\n")))))
          (test "SIGTERM: the lab and its view stop" 0 (stop-process! pid))
          (let* ((trace (in-dir "logs/view.jsonl"))
                 (replay-port (+ (test-lab-port-base lab) 146))
                 (replay (start-process! (list (tool-path "bin/murdoch") "replay" trace
                                               (number->string replay-port))
                                         (in-dir "replay.out"))))
            (test "the replay serves the page" #t (wait-for-port replay-port 30))
            (test "its trace is the run's" #t
              (string=? (file-text trace) (or (http-get replay-port "/trace") "")))
            (if chromium
                (let ((dom (browser-dom (string-append "http://127.0.0.1:"
                                                       (number->string replay-port) "/")
                                        (in-dir "replay.html"))))
                  (test "in the browser: a replay" #t (text-contains? dom "replay of"))
                  (test "with each robot and the task" '(#t #t #t)
                    (map (lambda (w) (text-contains? dom w))
                         (list "<tr data-name=\"moseley\"" "<tr data-name=\"ernst\""
                               "drive-a-while")))))
            (stop-process! replay))))))

;; A lab whose user named no --logs folder keeps the view's trace in the
;; runs/ of the folder it was started from.
(if (file-exists? (tool-path "sim/b14"))
    (let* ((out (in-dir "lab-runs.out"))
           (pid (start-process!
                 (list "sh" "-c" "cd \"$0\" && exec \"$1\" lab \"$2\" --view"
                       dir (tool-path "bin/murdoch") (test-lab-file lab))
                 out)))
      (wait-until 90 (lambda () (text-contains? (file-text out) "lab: ready")))
      (test "without --logs, the lab names a trace in runs/" #t
        (text-contains? (file-text out) "lab: the view's trace: runs/test-"))
      (stop-process! pid)
      (test "and it is there, under the folder the lab started in" #t
        (any (lambda (f) (string-prefix? "test-" f))
             (if (file-exists? (in-dir "runs")) (directory-files (in-dir "runs")) '())))))

(test-end)
(remove-test-lab! lab)
(test-exit)
