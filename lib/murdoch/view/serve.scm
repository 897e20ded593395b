;;;; Serving the live view, part of (murdoch view): the page, the trace,
;;;; the snapshots as they come, and the loop that polls the lab.

(define content-types
  '(("html" . "text/html; charset=UTF-8")
    ("js" . "text/javascript; charset=UTF-8")
    ("css" . "text/css; charset=UTF-8")))

(define (respond request status type body)
  (servlet-respond request status (if (= status 200) "OK" "Not Found")
                   `((Content-Type . ,type)
                     (Content-Length . ,(bytevector-length (string->utf8 body)))
                     (Cache-Control . "no-cache")
                     (Connection . "close")))
  (write-string body (request-out request)))

;; The servlet: web's files, /info, /trace, /state and /events (no feed in a replay).
(define (view-servlet web trace feed info)
  (lambda (cfg request next restart)
    (let ((path (request-path request)))
      (cond
       ((member path '("/" "/index.html"))
        (respond request 200 (cdr (assoc "html" content-types))
                 (file->string (string-append web "/view.html"))))
       ((member path '("/view.js" "/view.css"))
        (respond request 200
                 (cdr (assoc (if (equal? path "/view.js") "js" "css") content-types))
                 (file->string (string-append web path))))
       ((equal? path "/info")
        (respond request 200 "application/json" (json-text (info))))
       ((equal? path "/trace")
        (respond request 200 "text/plain; charset=UTF-8"
                 (if (file-exists? trace) (file->string trace) "")))
       ((and feed (equal? path "/state"))
        (respond request 200 "application/json"
                 (let ((r (feed-recent feed))) (if (pair? r) (cdar r) "null"))))
       ((and feed (equal? path "/events"))
        (send-events request feed))
       (else (respond request 404 "text/plain" "not found\n"))))))

;; Server-sent events from snapshot ?from=N or after Last-Event-ID, until
;; the page goes (a comment after 10 s quiet finds it gone); ?once=1 sends
;; what there is and ends.
(define (send-events request feed)
  (let ((out (request-out request))
        (once? (request-param request "once")))
    (servlet-respond request 200 "OK"
                     '((Content-Type . "text/event-stream")
                       (Cache-Control . "no-cache")))
    (guard (e (#t #f))                  ; the page went away
      (let loop ((next (first-event request feed)))
        (let ((new (feed-after feed next (if once? 0 10))))
          (for-each (lambda (r)
                      (write-string (string-append "id: " (number->string (car r))
                                                   "\ndata: " (cdr r) "\n\n")
                                    out))
                    new)
          (if (and (null? new) (not once?)) (write-string ":\n\n" out))
          (flush-output-port out)
          (unless once?
            (loop (if (pair? new) (+ 1 (car (last new))) next))))))))

(define (first-event request feed)
  (or (let ((id (assq 'last-event-id (request-headers request))))
        (and id (string? (cdr id))
             (let ((n (string->number (cdr id)))) (and n (+ n 1)))))
      (let ((p (request-param request "from")))
        (and p (string->number p)))
      (feed-count feed)))

(define (listen-on port)
  (let ((addr (get-address-info "127.0.0.1" port)))
    (guard (e (#t (error (string-append "the view cannot listen on 127.0.0.1:"
                                        (number->string port)
                                        " (is another process there?)"))))
      (make-listener-socket addr))))

(define (serve! listener servlet)
  (run-http-server listener servlet (make-conf '((quiet? . #t)) #f #f #f)))

(define (say . parts)
  (for-each display parts)
  (newline)
  (flush-output-port (current-output-port)))

;;> `murdoch view LAB [PORT]`: joins the running lab, polls it twice a
;;> second, appends each snapshot to \var{trace} (#f: runs/LAB-SECONDS.jsonl)
;;> and serves the page from \var{web} on 127.0.0.1:\var{port}, until killed.
(define (run-view web lab-file port trace)
  (set-process-name! "murdoch-view")
  (let* ((lab (read-lab lab-file))
         (port (or port (lab-planned-port lab 'view)))
         (listener (listen-on port))
         (trace (or trace (default-trace lab)))
         (uid (string->symbol
               (string-append "view-" (number->string (current-process-id)))))
         ;; Its own port, not a guest's: a REPL that drew the same would not start.
         (env (join-lab lab-file uid (lab-planned-port lab 'view-peer)))
         (proc (eval report-source (make-repl-environment lab env)))
         (aspaces (map (lambda (a) (uid->aspace (lab-aspace-uid a))) (lab-aspaces lab)))
         (header (or (trace-header trace) (lab-header lab)))
         (state (new-view-state header))
         (out (open-trace trace header))
         (feed (make-feed trace out (max 0 (- (trace-line-count trace) 1))))
         (start (cdr (assq 'started header))))
    (tell-who-is-away lab)
    (thread-start!
     (make-logged-thread
      (lambda ()
        (let loop ()
          ;; The trace counts wall-clock seconds; looks are due by the monotonic clock.
          (let ((t0 (monotonic-seconds))
                (at (- (utc-seconds) start)))
            (feed-add! feed (json-text
                                    (parameterize ((remote-timeout 1))
                                      (view-snapshot lab at
                                                     (remote-apply-all aspaces proc)
                                                     state (lab-line)))))
            (thread-sleep! (max 0.05 (- (+ t0 poll-seconds) (monotonic-seconds))))
            (loop))))
      'view-poll))
    (say "view: http://127.0.0.1:" port "/ (trace " trace ")")
    (serve! listener
            (view-servlet web trace feed
                          (lambda ()
                            `((live . #t) (lab . ,(symbol->string (lab-name lab)))
                              (trace . ,trace)))))))

;; The header of the trace at path, or #f: a restarted view carries on.
(define (trace-header path)
  (and (file-exists? path)
       (let ((line (call-with-input-file path read-line)))
         (and (string? line)
              (guard (e (#t #f)) (string->json line))))))

(define (trace-line-count path)
  (if (file-exists? path)
      (call-with-input-file path
        (lambda (in)
          (let loop ((n 0))
            (if (eof-object? (read-line in)) n (loop (+ n 1))))))
      0))

;; The trace's port: a new file that starts with header, or the trace's end.
(define (open-trace path header)
  (if (trace-header path)
      (open-output-file-descriptor
       (open path (bitwise-ior open/write open/append)))
      (let ((out (open-output-file path)))
        (write-string (json-text header) out)
        (newline out)
        (flush-output-port out)
        out)))

;;> runs/LAB-SECONDS.jsonl, or -2 and on when taken: claimed by making the file.
(define (default-trace lab)
  (let ((dir "runs")
        (stem (string-append "runs/" (symbol->string (lab-name lab)) "-"
                             (number->string (exact (floor (utc-seconds)))))))
    (if (not (file-exists? dir)) (create-directory* dir))
    (let claim ((n 1))
      (let* ((name (string-append stem
                                  (if (= n 1) "" (string-append "-" (number->string n)))
                                  ".jsonl"))
             (fd (open name (bitwise-ior open/write open/create open/exclusive) #o644)))
        (cond (fd (close-port (open-output-file-descriptor fd)) name)
              ((file-exists? name) (claim (+ n 1)))
              (else (error (string-append "cannot make the trace " name))))))))

;;> `murdoch replay TRACE [PORT]`: serves the page on 127.0.0.1:\var{port} to play \var{trace}.
(define (run-replay web trace port)
  (if (not (file-exists? trace)) (error (string-append "no such trace " trace)))
  (let ((header (trace-header trace)))
    (if (not (and (list? header) (equal? (assq 'kind header) '(kind . "lab"))))
        (error (string-append "not a trace of the view: " trace " (a trace's first"
                              " line is the view's header of the room)"))))
  (let* ((port (or port (planned-port (unread-lab-port-base) 'view)))
         (listener (listen-on port)))
    (say "view: http://127.0.0.1:" port "/ (replaying " trace ")")
    (serve! listener
            (view-servlet web trace #f
                          (lambda () `((live . #f) (trace . ,trace)))))))
